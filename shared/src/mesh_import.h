// Reading a mesh file through Assimp, hardened against hostile files: PLY headers checked
// first, reads on a budget, the raw import checked before post-processing. Private to
// shared/src.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "rvr/shared/scene.h"

namespace rvr::scene_load {

// `file` relative to `base_dir`; `path` is the JSON path for errors. Faces that are not
// triangles are counted in `skipped_primitives`. All of the file's meshes in one.
TriangleMesh import_mesh(const std::string& file, const std::string& base_dir,
                         const std::string& path, bool smooth, size_t* skipped_primitives);

// One mesh of a model file with its own material (the file's meshes are joined by material).
struct ModelPart {
  std::string name;
  TriangleMesh mesh;                 // vertex normals when the file has them, else flat
  std::optional<Material> material;  // empty: the file gives none (use the default)
  bool textured = false;             // has a colour texture, which is not sampled
};

// What a model file holds beyond its triangles: its first camera and its point lights, in
// world space, and its meshes one by one.
struct ImportedModel {
  std::vector<ModelPart> parts;
  std::optional<Camera> camera;
  float camera_aspect = 0.0f;  // width / height, 0 when the file does not say
  // The up direction of the file's coordinates as Assimp gives them, from the file's metadata
  // (FBX's UpAxis and UpAxisSign); +y where the file says nothing or Assimp has turned it
  // already (Collada's <up_axis>, 3DS).
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  std::vector<Light> lights;
  // Lights whose intensity does not fall off with distance (no quadratic or linear
  // attenuation, e.g. Collada's default): their index in `lights`.
  std::vector<size_t> unattenuated_lights;
  size_t skipped_primitives = 0;
  std::vector<std::string> warnings;
};

ImportedModel import_model(const std::string& file, const std::string& base_dir,
                           const std::string& path);

}  // namespace rvr::scene_load
