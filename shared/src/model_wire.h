// Imported meshes and models as bytes, to carry them out of the isolated import process
// (isolated_call.h) and back. Private to shared/src.
#pragma once

#include <string>

#include "mesh_import.h"

namespace rvr::scene_load {

std::string encode(const TriangleMesh& mesh, size_t skipped_primitives);
std::string encode(const ImportedModel& model);
// Throw std::runtime_error on bytes that are not what encode() wrote.
TriangleMesh decode_mesh(const std::string& bytes, size_t* skipped_primitives);
ImportedModel decode_model(const std::string& bytes);

}  // namespace rvr::scene_load
