// mesh_import.h's functions in the program: the model-import plugin (model_import_abi.h) opened
// on first use and called through its table, so that Assimp is loaded only by a run that reads
// a model or mesh file.
#include <stddef.h>
#include <stdint.h>

#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "allocation_budget.h"
#include "mesh_import.h"
#include "model_import_abi.h"
#include "rvr/core/expected.h"
#include "rvr/core/plugin.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "scene_json_errors.h"

namespace rvr::scene_load {
namespace {

// The program's side of the budget and its operator new and delete (model_import_abi.h).
const ModelImportHost kHost = {
    [](AllocationBudget* storage, uint64_t bytes) { new (storage) AllocationBudget(bytes); },
    [](AllocationBudget* budget) { budget->~AllocationBudget(); },
    [](AllocationBudget* budget, uint64_t bytes) { budget->raise(bytes); },
    [](size_t bytes) { return ::operator new(bytes); },
    [](void* p) { ::operator delete(p); },
};

// The plugin's table, opened and connected once per process. Failing to load it is the
// installation's error, not the file's: an internal error (std::runtime_error) with the reason.
const rvr_model_import& plugin() {
  static const Expected<const rvr_model_import*> table = [] {
    Expected<const rvr_model_import*> t =
        open_plugin_table<rvr_model_import>("librvr_model_import.so", "rvr_model_import_get",
                                            RVR_MODEL_IMPORT_ABI_VERSION, "the model importer");
    if (t) (*t)->connect(&kHost);
    return t;
  }();
  if (!table) throw std::runtime_error(table.error().message);
  return **table;
}

}  // namespace

TriangleMesh import_mesh(const std::string& file, const std::string& base_dir,
                         const std::string& path, bool smooth, size_t* skipped_primitives,
                         std::vector<std::string>* warnings) {
  TriangleMesh mesh;
  LoadError error;
  if (!plugin().import_mesh(file, base_dir, path, smooth, skipped_primitives, warnings, &mesh,
                            &error))
    throw error;
  return mesh;
}

ImportedModel import_model(const std::string& file, const std::string& base_dir,
                           const std::string& path) {
  ImportedModel model;
  LoadError error;
  if (!plugin().import_model(file, base_dir, path, &model, &error)) throw error;
  return model;
}

bool model_extension_supported(const std::string& extension) {
  try {
    return plugin().extension_supported(extension);
  } catch (const std::runtime_error&) {
    return true;  // read as a model, whose import then says why the importer is missing
  }
}

}  // namespace rvr::scene_load
