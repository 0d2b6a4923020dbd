// Making a loaded mesh usable: the object's transform applied, degenerate triangles dropped,
// broken vertex normals repaired. Private to scene_io/src.
#pragma once

#include <cstddef>
#include <glm/glm.hpp>
#include <string>

#include "rvr/core/shapes/triangle_mesh.h"
#include "scene_transforms.h"

namespace rvr::scene_load {

bool finite(const glm::vec3& v);
// Whether the triangle is too thin to have a usable normal in floats.
bool degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);
// Applies the transform, drops degenerate triangles (counted in `dropped`) and repairs vertex
// normals that are zero or non-finite.
void finish_mesh(TriangleMesh& mesh, const Transform& t, const std::string& path, size_t* dropped,
                 size_t* repaired_normals);

}  // namespace rvr::scene_load
