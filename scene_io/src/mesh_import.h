// Reading a mesh file through Assimp, hardened against hostile files: PLY headers checked
// first, reads on a budget, the raw import checked before post-processing. Private to
// scene_io/src.
#pragma once

#include <cstddef>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/texture.h"

namespace rvr::scene_load {

// `file` relative to `base_dir`; `path` is the JSON path for errors. Faces that are not
// triangles are counted in `skipped_primitives`; what else was repaired or assumed (STL facet
// normals that contradict the winding, an unusable FBX unit) is added to `warnings`. All of
// the file's meshes in one, in metres where the file states its unit (Collada, FBX).
TriangleMesh import_mesh(const std::string& file, const std::string& base_dir,
                         const std::string& path, bool smooth, size_t* skipped_primitives,
                         std::vector<std::string>* warnings);

// A material's base-colour texture as the model file names it, before it is found and read.
struct ModelTexture {
  std::string file;  // as the file writes it; "*N" for the file's own image N (ImportedModel)
  TextureWrap wrap_u = TextureWrap::Repeat;
  TextureWrap wrap_v = TextureWrap::Repeat;
  UvTransform transform;  // glTF's KHR_texture_transform
};

// An image the model file holds itself (glTF data URIs and GLB buffers, FBX embedded media):
// a compressed image file's bytes (PNG, JPEG, ...: `format` its extension), or raw 8-bit RGB
// texels (`format` "rgb8", width x height, the top row first).
struct EmbeddedImage {
  std::string name;
  std::string format;
  int width = 0;
  int height = 0;
  std::string bytes;
};

// One mesh of a model file with its own material (the file's meshes are joined by material).
// The mesh keeps the texture coordinates of the set its base-colour texture uses (when it has
// one) and its vertex colours (linear RGB).
struct ModelPart {
  std::string name;
  TriangleMesh mesh;                    // vertex normals when the file has them, else flat
  std::optional<Material> material;     // empty: the file gives none (use the default)
  std::optional<ModelTexture> texture;  // the material's base-colour texture
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
  std::vector<EmbeddedImage> images;  // the file's own images that textures name "*N"
};

ImportedModel import_model(const std::string& file, const std::string& base_dir,
                           const std::string& path);

// Whether Assimp reads files of `extension` (".ply", lower case).
//
// In the program these three call the model-import plugin (model_import_loader.cpp), which
// holds this file's implementation (mesh_import.cpp) and Assimp (model_import_plugin.cpp).
// When the plugin cannot be loaded, every extension is a model's, and the import says why.
bool model_extension_supported(const std::string& extension);

}  // namespace rvr::scene_load
