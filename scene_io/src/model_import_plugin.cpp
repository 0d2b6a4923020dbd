// The model-import plugin (model_import_abi.h): mesh_import.cpp's Assimp import as a table.
// Built as librvr_model_import.so with its own copies of the few stateless helpers
// mesh_import.cpp uses; the allocation budget stays the opening program's
// (allocation_budget_plugin.cpp). The one part of rvr that links Assimp.
#include <stddef.h>

#include <assimp/Importer.hpp>
#include <string>
#include <vector>

#include "mesh_import.h"
#include "model_import_abi.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "scene_json_errors.h"

namespace rvr::scene_load {

// The program that opened the plugin (allocation_budget_plugin.cpp); null until connect().
extern const ModelImportHost* g_host;

namespace {

void connect(const ModelImportHost* host) {
  g_host = host;
}

bool mesh(const std::string& file, const std::string& base_dir, const std::string& path,
          bool smooth, size_t* skipped_primitives, std::vector<std::string>* warnings,
          TriangleMesh* out, LoadError* error) {
  try {
    *out = import_mesh(file, base_dir, path, smooth, skipped_primitives, warnings);
    return true;
  } catch (const LoadError& e) {
    *error = e;
    return false;
  }
}

bool model(const std::string& file, const std::string& base_dir, const std::string& path,
           ImportedModel* out, LoadError* error) {
  try {
    *out = import_model(file, base_dir, path);
    return true;
  } catch (const LoadError& e) {
    *error = e;
    return false;
  }
}

bool extension_supported(const std::string& extension) {
  return Assimp::Importer().IsExtensionSupported(extension);
}

}  // namespace
}  // namespace rvr::scene_load

extern "C" __attribute__((visibility("default"))) const rvr_model_import* rvr_model_import_get() {
  static const rvr_model_import table = {
      RVR_MODEL_IMPORT_ABI_VERSION,
      &rvr::scene_load::connect,
      &rvr::scene_load::mesh,
      &rvr::scene_load::model,
      &rvr::scene_load::extension_supported,
  };
  return &table;
}
