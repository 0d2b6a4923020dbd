// Loading and validating rvr-scene/1 files and built-in scenes.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

// Reads and validates a scene file. Errors name the file, the JSON path and what is wrong:
// "scenes/bad.json: objects[3].radius: must be > 0, got -1" or
// "scenes/bad.json:12:5: JSON syntax: expected ',' or '}'".
Expected<Scene> load_scene_file(const std::string& path);

// Parses scene JSON text; `source` names it in messages and `base_dir` resolves mesh paths.
Expected<Scene> parse_scene(const std::string& json_text, const std::string& source,
                            const std::string& base_dir);

// What the command line may change in a scene as it is loaded.
// The largest exposure, in stops either way (image.exposure, --exposure).
constexpr float kMaxExposure = 64.0f;
// The largest image width and height (image.width/height, --width, --height, --image).
constexpr int kMaxImageSize = 16384;

// Model files: which axis of the file's coordinates (as Assimp reads them) is up. Auto: FBX
// from its UpAxis/UpAxisSign; every other format +y (Assimp has already turned Collada's
// <up_axis> and 3DS's +z to +y; glTF is +y; OBJ, STL, PLY say nothing). Z: +z is up.
enum class UpAxis { Auto, Y, Z };
// Model files: the file's own camera or lights where it has them (File), or rvr's framing
// camera and default key light whatever the file holds (Auto).
enum class FromFile { File, Auto };

struct SceneOverrides {
  std::optional<int> width, height;  // the image size (before the camera is framed)
  // Frame the scene from this direction (from the centre towards the eye; see
  // camera_framing.h), replacing the camera of the scene or model file.
  std::optional<glm::vec3> view_from;
  // ImageSettings::exposure for any scene; unset: the scene file's, or for a model file the
  // automatic exposure (docs/scene-format.md, "Model files as scenes").
  std::optional<float> exposure;
  UpAxis up = UpAxis::Auto;          // model files only
  FromFile camera = FromFile::File;  // model files only
  // Model files, camera File: a file camera that does not frame the model (view_of_model in
  // camera_framing.h) is replaced by the framing camera with a warning; false keeps it as it is.
  bool judge_file_camera = true;
  FromFile lights = FromFile::File;  // model files only
};

// "builtin:NAME" or a path: a scene file, or a model file in any format Assimp reads (see
// load_model_scene).
Expected<Scene> load_scene(const std::string& spec, const SceneOverrides& overrides = {});

// Whether `path` names a model file by its extension: one Assimp reads, other than .json.
// (Files with an extension Assimp does not know are read as scenes unless their content is a
// model Assimp recognises; see docs/scene-format.md.)
bool is_model_file_name(const std::string& path);

// A model file as a scene (docs/scene-format.md, "Model files as scenes"): one object per
// mesh with the file's own material, turned so that its up axis (overrides.up) is +y; the
// file's first camera (not an FBX exporter's viewport camera, nor, unless
// overrides.judge_file_camera is false, one that does not frame the model), else one framing
// the model from default_view_from() (overrides.view_from replaces either, overrides.camera =
// Auto always frames); the file's point lights, else (or with overrides.lights = Auto) a key
// light near the camera and ambient; the automatic exposure unless overrides.exposure is set.
Expected<Scene> load_model_scene(const std::string& path, const SceneOverrides& overrides = {});

// A triangle mesh from memory (positions, triangles, optionally one normal and one linear RGB
// colour per vertex) as a scene, as a model file holding only that mesh is one (above): the
// framing camera, the default lights, the automatic exposure, degenerate triangles dropped with
// a warning; overrides.up is Y or Z (Auto: Y). `source` names it in messages. Bad input: an
// index past the vertices, a non-finite position, normals or colours not one per vertex, no
// triangle.
Expected<Scene> load_mesh_scene(TriangleMesh mesh, const std::string& source,
                                const SceneOverrides& overrides = {});

// Scene JSON text as load_scene reads a scene file of that text: `source` names it in messages,
// mesh files are found from `base_dir`, the overrides apply as to a scene file.
Expected<Scene> load_scene_text(const std::string& json_text, const std::string& source,
                                const std::string& base_dir, const SceneOverrides& overrides = {});

struct BuiltinSceneInfo {
  std::string name;         // e.g. "occluders:N"
  std::string description;  // one line
};
std::vector<BuiltinSceneInfo> builtin_scenes();

// NAME as in "cornell", "soup:1000".
Expected<Scene> make_builtin_scene(const std::string& name);

}  // namespace rvr
