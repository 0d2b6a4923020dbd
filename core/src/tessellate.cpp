#include "rvr/core/tessellate.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "rvr/core/check.h"

namespace rvr {

std::array<glm::vec3, 2> plane_axes(const glm::vec3& n) {
  // Any unit vector not parallel to n seeds the basis; pick the world axis least aligned with n
  // so the cross products are well conditioned.
  glm::vec3 a = std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  glm::vec3 u = glm::normalize(glm::cross(a, n));
  glm::vec3 v = glm::cross(n, u);
  return {u, v};
}

TriangleMesh tessellate_sphere(const Sphere& s, int segments) {
  segments = std::max(segments, 3);
  int rings = std::max(segments / 2, 2);
  TriangleMesh mesh;
  const float pi = 3.14159265358979323846f;
  // Vertex (ring r, longitude k); poles are single vertices.
  auto add_vertex = [&](const glm::vec3& dir) {
    mesh.positions.push_back(s.center + s.radius * dir);
    mesh.normals.push_back(dir);
  };
  add_vertex({0, 1, 0});  // north pole: index 0
  for (int r = 1; r < rings; ++r) {
    float theta = pi * float(r) / float(rings);
    for (int k = 0; k < segments; ++k) {
      float phi = 2.0f * pi * float(k) / float(segments);
      add_vertex(
          {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)});
    }
  }
  uint32_t south = uint32_t(mesh.positions.size());
  add_vertex({0, -1, 0});
  auto ring_vertex = [&](int r, int k) {
    return uint32_t(1 + (r - 1) * segments + (k % segments));
  };
  // Counter-clockwise seen from outside: longitude k grows counter-clockwise seen from +y.
  for (int k = 0; k < segments; ++k)
    mesh.triangles.push_back({0, ring_vertex(1, k), ring_vertex(1, k + 1)});
  for (int r = 1; r < rings - 1; ++r) {
    for (int k = 0; k < segments; ++k) {
      uint32_t a = ring_vertex(r, k), b = ring_vertex(r, k + 1);
      uint32_t c = ring_vertex(r + 1, k), d = ring_vertex(r + 1, k + 1);
      mesh.triangles.push_back({a, c, d});
      mesh.triangles.push_back({a, d, b});
    }
  }
  for (int k = 0; k < segments; ++k)
    mesh.triangles.push_back({south, ring_vertex(rings - 1, k + 1), ring_vertex(rings - 1, k)});
  RVR_CHECK(mesh.positions.size() == size_t(2 + (rings - 1) * segments) &&
                mesh.triangles.size() == size_t(2 * segments * (rings - 1)) &&
                mesh.triangles.size() == sphere_triangle_count(segments),
            "a UV sphere of ", segments, " longitudes and ", rings, " rings has ",
            2 * segments * (rings - 1), " triangles, not ", mesh.triangles.size());
  RVR_CHECK(ring_vertex(rings - 1, segments - 1) < south, "ring vertices come before the pole");
  return mesh;
}

TriangleMesh tessellate_plane(const Square& p) {
  const std::array<glm::vec3, 4> corners = plane_corners(p);
  TriangleMesh mesh;
  mesh.positions.assign(corners.begin(), corners.end());
  // u x v = n, so (u, v) order is counter-clockwise seen from the normal's side.
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  RVR_CHECK(mesh.triangles.size() == kPlaneTriangleCount, "a square is ", kPlaneTriangleCount,
            " triangles");
  return mesh;
}

std::array<glm::vec3, 4> plane_corners(const Square& p) {
  auto [u, v] = plane_axes(p.normal);
  float h = p.half_size;
  return {p.point - h * u - h * v, p.point + h * u - h * v, p.point + h * u + h * v,
          p.point - h * u + h * v};
}

uint64_t sphere_triangle_count(int segments) {
  segments = std::max(segments, 3);  // as tessellate_sphere
  const uint64_t rings = uint64_t(std::max(2, segments / 2));
  return uint64_t(segments) * (2 * rings - 2);
}

int sphere_segments_for_triangles(size_t triangles) {
  // segments longitudes and segments/2 rings give segments * (segments - 2) triangles.
  int s = int(std::lround(1.0 + std::sqrt(1.0 + double(triangles))));
  return std::max(s, 3);
}

}  // namespace rvr
