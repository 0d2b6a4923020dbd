// The interface of the model-import plugin, librvr_model_import.so (model_import_plugin.cpp):
// mesh_import.cpp's Assimp import behind a table of functions. model_import_loader.cpp opens it
// on first use, so that only a run that reads a model or mesh file loads Assimp
// (docs/design.md, "Start-up"). Both sides are built together from this header; the version
// refuses a plugin of another build. Private to scene_io/src.
#pragma once

#include <stddef.h>

#include <cstdint>
#include <string>
#include <vector>

#include "allocation_budget.h"
#include "mesh_import.h"
#include "rvr/core/scene.h"
#include "scene_json_errors.h"

#define RVR_MODEL_IMPORT_ABI_VERSION 1

namespace rvr::scene_load {

// What the plugin's import code takes from the program that opened it. The allocation budget
// (allocation_budget.h) counts in the program's own operator new: the import's budgets must
// be the program's objects, constructed, raised and destroyed by its code, and the plugin's
// operator new and delete (which Assimp uses where the program's are not found first: in the
// Python module) forward to the program's.
struct ModelImportHost {
  void (*budget_construct)(AllocationBudget* storage, uint64_t bytes);
  void (*budget_destroy)(AllocationBudget* budget);
  void (*budget_raise)(AllocationBudget* budget, uint64_t bytes);
  void* (*allocate)(size_t bytes);  // the program's ::operator new
  void (*release)(void* p);         // the program's ::operator delete
};

}  // namespace rvr::scene_load

extern "C" {

struct rvr_model_import {
  int abi_version;  // RVR_MODEL_IMPORT_ABI_VERSION
  // Called once, before anything else. `host` outlives the plugin.
  void (*connect)(const rvr::scene_load::ModelImportHost* host);
  // import_mesh and import_model of mesh_import.h; a LoadError they throw comes back in
  // `error` with false.
  bool (*import_mesh)(const std::string& file, const std::string& base_dir, const std::string& path,
                      bool smooth, size_t* skipped_primitives, std::vector<std::string>* warnings,
                      rvr::TriangleMesh* mesh, rvr::scene_load::LoadError* error);
  bool (*import_model)(const std::string& file, const std::string& base_dir,
                       const std::string& path, rvr::scene_load::ImportedModel* model,
                       rvr::scene_load::LoadError* error);
  // Whether Assimp reads files of `extension` (".ply", lower case).
  bool (*extension_supported)(const std::string& extension);
};

// The table; with the operator new and delete forms, the plugin's only exported symbols.
const struct rvr_model_import* rvr_model_import_get(void);
}
