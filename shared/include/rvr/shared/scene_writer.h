// Writing a Scene as an rvr-scene/1 document that the loader reads back to the same scene.
#pragma once

#include <string>
#include <vector>

#include "rvr/shared/expected.h"
#include "rvr/shared/scene.h"

namespace rvr {

// A mesh the document names in a `mesh` object's `file`: rvr-scene/1 holds only single
// triangles inline, so a mesh of more triangles (or one with vertex normals) goes to a binary
// little-endian PLY file.
struct SceneMeshFile {
  std::string name;   // as written in the document, relative to the document's folder
  std::string bytes;  // the PLY file
};

struct SceneDocument {
  std::string json;                       // the rvr-scene/1 text, ending in a newline
  std::vector<SceneMeshFile> mesh_files;  // to be written next to the document
};

// Writes `scene` as rvr-scene/1. Every key is written, defaults included; floats are written
// as the shortest decimal that reads back to the same float. An object of type Triangles
// with exactly one triangle and no normals becomes a `triangle` object; any other mesh
// becomes a `mesh` object whose file is named mesh_prefix + ".mesh" + object index + ".ply".
// Fails (bad input) on what the format cannot express: a materials[0] that is not the
// built-in default, duplicate or empty material names, a material index out of range.
Expected<SceneDocument> write_scene(const Scene& scene, const std::string& mesh_prefix);

}  // namespace rvr
