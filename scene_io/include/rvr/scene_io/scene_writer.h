// Writing a Scene as an rvr-scene/1 document that the loader reads back to the same scene.
#pragma once

#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/image_codec/image_io.h"

namespace rvr {

// A mesh the document names in a `mesh` object's `file`: rvr-scene/1 holds only single
// triangles inline, so a mesh of more triangles (or one with vertex normals) goes to a binary
// little-endian PLY file.
struct SceneMeshFile {
  std::string name;   // as written in the document, relative to the document's folder
  std::string bytes;  // the PLY file
};

// A texture the document names that exists in memory only (a model file's embedded image, a
// built-in scene's texture): its level 0 as a linear EXR, which reads back to the same texels.
struct SceneTextureFile {
  std::string name;  // as written in the document, relative to the document's folder
  Image image;       // to be written with write_image
};

// A texture file the document names beside itself, to be copied there from where the scene
// read it (write_scene's copy_texture_files).
struct SceneCopiedFile {
  std::string name;    // as written in the document, relative to the document's folder
  std::string source;  // the file the scene read
};

struct SceneDocument {
  std::string json;                             // the rvr-scene/1 text, ending in a newline
  std::vector<SceneMeshFile> mesh_files;        // to be written next to the document
  std::vector<SceneTextureFile> texture_files;  // likewise
  std::vector<SceneCopiedFile> copied_files;    // to be copied next to the document
};

// Writes `scene` as rvr-scene/1. Every key is written, defaults included; floats are written
// as the shortest decimal that reads back to the same float. An object of type Triangles
// with exactly one triangle and no normals becomes a `triangle` object (with its `uvs` and
// `colors`); any other mesh becomes a `mesh` object whose file is named mesh_prefix + ".mesh"
// + object index + ".ply" (texture coordinates and vertex colours as float properties s, t and
// red, green, blue). A texture read from a file under `document_folder` (the folder the
// document is written to) is named by its path relative to that folder; one elsewhere by its
// absolute path (a relative path climbing out of the folder would break when the folder
// moves), or, with `copy_texture_files`, by mesh_prefix + ".texture" + index + its extension,
// a copy to be made beside the document (copied_files). A texture in memory only goes to
// mesh_prefix + ".texture" + index + ".exr"; one that was not found keeps the name it had.
// Fails (bad input) on what the format cannot express: a materials[0] that is not the built-in
// default, duplicate or empty material names, a material index out of range.
Expected<SceneDocument> write_scene(const Scene& scene, const std::string& mesh_prefix,
                                    const std::string& document_folder = ".",
                                    bool copy_texture_files = false);

}  // namespace rvr
