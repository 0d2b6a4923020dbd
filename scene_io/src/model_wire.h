// Imported meshes and models as bytes, to carry them out of the isolated import process
// (isolated_call.h) and back. Private to scene_io/src.
#pragma once

#include <stddef.h>

#include <string>
#include <vector>

#include "mesh_import.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr::scene_load {

std::string encode(const TriangleMesh& mesh, size_t skipped_primitives,
                   const std::vector<std::string>& warnings);
std::string encode(const ImportedModel& model);
// Throw std::runtime_error on bytes that are not what encode() wrote.
// decode_mesh adds to `skipped_primitives` and appends to `warnings`.
TriangleMesh decode_mesh(const std::string& bytes, size_t* skipped_primitives,
                         std::vector<std::string>* warnings);
ImportedModel decode_model(const std::string& bytes);

}  // namespace rvr::scene_load
