// Making a loaded mesh usable (see mesh_repair.h).
#include "mesh_repair.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace rvr::scene_load {

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Twice the area, and whether the triangle is too thin to have a usable normal in floats.
bool degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  glm::vec3 nf = glm::cross(b - a, c - a);
  float lf = glm::length(nf);
  if (!(lf > 0.0f) || !std::isfinite(lf)) return true;
  glm::dvec3 e1 = glm::dvec3(b) - glm::dvec3(a), e2 = glm::dvec3(c) - glm::dvec3(a),
             e3 = glm::dvec3(c) - glm::dvec3(b);
  double longest = std::max({glm::dot(e1, e1), glm::dot(e2, e2), glm::dot(e3, e3)});
  return glm::length(glm::cross(e1, e2)) <= 1e-10 * longest;
}

// Applies the transform, drops degenerate triangles (counted in `dropped`) and repairs vertex
// normals that are zero or non-finite.
void finish_mesh(TriangleMesh& mesh, const Transform& t, const std::string& path, size_t* dropped,
                 size_t* repaired_normals) {
  if (!t.identity) {
    for (glm::vec3& p : mesh.positions) p = to_float(t.point(glm::dvec3(p)), path, "a vertex");
  }
  std::vector<char> bad_normal(mesh.normals.size(), 0);
  for (size_t i = 0; i < mesh.normals.size(); ++i) {
    glm::dvec3 n = t.normal(glm::dvec3(mesh.normals[i]));
    double len = glm::length(n);
    if (!std::isfinite(len) || len < 1e-20) {
      bad_normal[i] = 1;
      continue;
    }
    mesh.normals[i] = glm::vec3(n / len);
    if (!finite(mesh.normals[i])) bad_normal[i] = 1;
  }
  std::vector<glm::uvec3> kept;
  kept.reserve(mesh.triangles.size());
  for (const glm::uvec3& tri : mesh.triangles) {
    if (tri.x == tri.y || tri.y == tri.z || tri.x == tri.z ||
        degenerate(mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z])) {
      ++*dropped;
      continue;
    }
    kept.push_back(tri);
  }
  mesh.triangles = std::move(kept);
  mesh.triangles.shrink_to_fit();
  if (std::find(bad_normal.begin(), bad_normal.end(), 1) == bad_normal.end()) return;
  for (const glm::uvec3& tri : mesh.triangles) {
    glm::vec3 face = glm::normalize(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                                               mesh.positions[tri.z] - mesh.positions[tri.x]));
    for (int k = 0; k < 3; ++k) {
      if (bad_normal[tri[k]] == 1 && finite(face)) {
        mesh.normals[tri[k]] = face;
        bad_normal[tri[k]] = 2;
        ++*repaired_normals;
      }
    }
  }
  for (size_t i = 0; i < bad_normal.size(); ++i) {
    if (bad_normal[i] == 1) mesh.normals[i] = glm::vec3(0.0f, 0.0f, 1.0f);  // unused vertex
  }
}

}  // namespace rvr::scene_load
