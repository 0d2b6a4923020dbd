#include "rvr/core/shapes/csg.h"

#include <stddef.h>

#include <cmath>
#include <glm/glm.hpp>

#include "rvr/core/tessellate.h"

namespace rvr {
namespace {

// CSG along one line: every leaf gives an interval of the whole line; a sweep over the sorted
// boundaries tracks inside(A) and inside(B) per node and keeps the boundaries where the node's
// inside changes. A subtracted solid's boundary is reversed: its outward normal points into the
// result.
void collect_leaves(const CsgNode* node, std::vector<Sphere>& leaves) {
  if (node->is_leaf) {
    leaves.push_back(node->sphere);
    return;
  }
  collect_leaves(node->a.get(), leaves);
  collect_leaves(node->b.get(), leaves);
}

void csg_boundaries(const CsgNode* node, const CsgInterval* leaves, uint32_t& next_leaf,
                    std::vector<CsgBoundary>& out) {
  if (node->is_leaf) {
    uint32_t leaf = next_leaf++;
    const CsgInterval& i = leaves[leaf];
    if (i.hit && i.enter < i.leave) {
      out.push_back({i.enter, true, leaf, false, i.enter_facet});
      out.push_back({i.leave, false, leaf, false, i.leave_facet});
    }
    return;
  }
  std::vector<CsgBoundary> a, b;
  csg_boundaries(node->a.get(), leaves, next_leaf, a);
  csg_boundaries(node->b.get(), leaves, next_leaf, b);
  // Both lists are sorted and alternate enter/exit; merge them in t order.
  bool in_a = false, in_b = false;
  auto inside = [&](bool ia, bool ib) {
    switch (node->op) {
      case CsgOp::Union:
        return ia || ib;
      case CsgOp::Intersection:
        return ia && ib;
      case CsgOp::Difference:
        return ia && !ib;
    }
    return false;
  };
  size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    bool from_a = j >= b.size() || (i < a.size() && a[i].t <= b[j].t);
    CsgBoundary e = from_a ? a[i++] : b[j++];
    bool before = inside(in_a, in_b);
    (from_a ? in_a : in_b) = e.entering;
    bool after = inside(in_a, in_b);
    if (before == after) continue;
    if (!from_a && node->op == CsgOp::Difference) e.flip = !e.flip;
    e.entering = after;
    out.push_back(e);
  }
}

// Where the whole line o + t d crosses the closed convex mesh: its smallest and largest
// crossing (a line meets a convex surface at most twice), in double precision; false when it
// misses or only grazes it.
CsgInterval mesh_interval(const Ray& ray, const TriangleMesh& mesh) {
  const glm::dvec3 o(ray.origin), d(ray.dir);
  CsgInterval out;
  double lo = INFINITY, hi = -INFINITY;
  for (uint32_t k = 0; k < uint32_t(mesh.triangles.size()); ++k) {
    const glm::uvec3& tri = mesh.triangles[k];
    const glm::dvec3 p0(mesh.positions[tri.x]), p1(mesh.positions[tri.y]),
        p2(mesh.positions[tri.z]);
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, q = glm::cross(d, e2);
    const double det = glm::dot(e1, q);
    if (det == 0.0) continue;  // the line lies in the triangle's plane
    const glm::dvec3 s = o - p0;
    const double u = glm::dot(s, q) / det;
    if (u < 0.0 || u > 1.0) continue;
    const glm::dvec3 r = glm::cross(s, e1);
    const double v = glm::dot(d, r) / det;
    if (v < 0.0 || u + v > 1.0) continue;
    const double t = glm::dot(e2, r) / det;
    if (t < lo) {
      lo = t;
      out.enter_facet = k;
    }
    if (t > hi) {
      hi = t;
      out.leave_facet = k;
    }
  }
  out.hit = lo < hi;
  out.enter = lo;
  out.leave = hi;
  return out;
}

void leaf_balls(const CsgNode* node, std::vector<BoundingBall>& out) {
  if (!node) return;
  if (node->is_leaf) {
    node->sphere.bounding_balls(out);
    return;
  }
  leaf_balls(node->a.get(), out);
  leaf_balls(node->b.get(), out);
}

}  // namespace

bool first_csg_boundary(const CsgNode* root, const CsgInterval* leaves, double t_min, double t_max,
                        CsgBoundary& out) {
  std::vector<CsgBoundary> boundaries;
  uint32_t next_leaf = 0;
  csg_boundaries(root, leaves, next_leaf, boundaries);
  for (const CsgBoundary& e : boundaries) {
    if (e.t <= t_min) continue;
    if (e.t >= t_max) return false;
    out = e;
    return true;
  }
  return false;
}

std::vector<Sphere> csg_leaves(const CsgNode* root) {
  std::vector<Sphere> leaves;
  collect_leaves(root, leaves);
  return leaves;
}

// Any CSG result lies inside the union of its leaves.
void CsgSolid::bounding_balls(std::vector<BoundingBall>& out) const {
  leaf_balls(root, out);
}

CsgSolid::Traced CsgSolid::traced() const {
  Traced t;
  t.root = root;
  collect_leaves(root, t.leaves);
  return t;
}

CsgSolid::Traced CsgSolid::traced(const TessellationOptions& options) const {
  Traced t = traced();
  if (!options.spheres_as_mesh) return t;
  for (const Sphere& leaf : t.leaves)
    t.leaf_meshes.push_back(tessellate_sphere(leaf, options.sphere_segments));
  t.leaf_triangles = uint32_t(sphere_triangle_count(options.sphere_segments));
  return t;
}

bool CsgSolid::Traced::intersect(const Ray& ray, ShapeHit& hit) const {
  std::vector<CsgInterval> intervals(leaves.size());
  for (size_t i = 0; i < leaves.size(); ++i) {
    float t0 = 0.0f, t1 = 0.0f;
    intervals[i].hit = sphere_interval(ray, leaves[i], t0, t1);
    intervals[i].enter = t0;
    intervals[i].leave = t1;
    // A tessellation lies inside its sphere: a line that misses the sphere misses it too.
    if (intervals[i].hit && !leaf_meshes.empty()) intervals[i] = mesh_interval(ray, leaf_meshes[i]);
  }
  CsgBoundary e;
  if (!first_csg_boundary(root, intervals.data(), ray.tmin, ray.tmax, e)) return false;
  hit.t = float(e.t);
  hit.part = leaf_meshes.empty() ? e.leaf : e.leaf * leaf_triangles + e.facet;
  hit.flip = e.flip;
  return true;
}

glm::vec3 CsgSolid::Traced::normal_at(const glm::vec3& position, const ShapeHit& hit) const {
  glm::vec3 n;
  if (leaf_meshes.empty()) {
    const Sphere& leaf = leaves[hit.part];
    n = (position - leaf.center) / leaf.radius;
  } else {
    // The vertex normals interpolated at the position's barycentrics in the triangle crossed.
    const TriangleMesh& mesh = leaf_meshes[hit.part / leaf_triangles];
    const glm::uvec3& tri = mesh.triangles[hit.part % leaf_triangles];
    const glm::vec3 &p0 = mesh.positions[tri.x], &p1 = mesh.positions[tri.y],
                    &p2 = mesh.positions[tri.z];
    const glm::vec3 e1 = p1 - p0, e2 = p2 - p0, f = position - p0;
    const float d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
    const float f1 = glm::dot(f, e1), f2 = glm::dot(f, e2), det = d11 * d22 - d12 * d12;
    const float u = det != 0.0f ? (d22 * f1 - d12 * f2) / det : 0.0f;
    const float v = det != 0.0f ? (d11 * f2 - d12 * f1) / det : 0.0f;
    n = glm::normalize((1.0f - u - v) * mesh.normals[tri.x] + u * mesh.normals[tri.y] +
                       v * mesh.normals[tri.z]);
  }
  return hit.flip ? -n : n;
}

glm::vec3 CsgSolid::Traced::geometric_normal_at(const glm::vec3& position,
                                                const ShapeHit& hit) const {
  if (leaf_meshes.empty()) return normal_at(position, hit);
  const TriangleMesh& mesh = leaf_meshes[hit.part / leaf_triangles];
  const glm::uvec3& tri = mesh.triangles[hit.part % leaf_triangles];
  const glm::vec3 n = glm::normalize(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                                                mesh.positions[tri.z] - mesh.positions[tri.x]));
  return hit.flip ? -n : n;
}

void CsgSolid::Traced::bounding_balls(std::vector<BoundingBall>& out) const {
  for (const Sphere& s : leaves) s.bounding_balls(out);
}

}  // namespace rvr
