#include "rvr/core/shapes/csg.h"

#include <stddef.h>

#include <glm/glm.hpp>

namespace rvr {
namespace {

// CSG along one ray: every leaf sphere gives an interval of the whole line; a sweep over
// the sorted boundaries tracks inside(A) and inside(B) per node and keeps the boundaries
// where the node's inside changes. A subtracted solid's boundary is reversed: its outward
// normal points into the result.
struct CsgBoundary {
  float t;
  bool entering;  // the result is entered here
  uint32_t leaf;  // depth-first leaf number
  bool flip;      // normal = -(sphere's outward normal)
};

void collect_leaves(const CsgNode* node, std::vector<Sphere>& leaves) {
  if (node->is_leaf) {
    leaves.push_back(node->sphere);
    return;
  }
  collect_leaves(node->a.get(), leaves);
  collect_leaves(node->b.get(), leaves);
}

void csg_boundaries(const CsgNode* node, const Ray& ray, uint32_t& next_leaf,
                    std::vector<CsgBoundary>& out) {
  if (node->is_leaf) {
    uint32_t leaf = next_leaf++;
    float t0, t1;
    if (sphere_interval(ray, node->sphere, t0, t1) && t0 < t1) {
      out.push_back({t0, true, leaf, false});
      out.push_back({t1, false, leaf, false});
    }
    return;
  }
  std::vector<CsgBoundary> a, b;
  csg_boundaries(node->a.get(), ray, next_leaf, a);
  csg_boundaries(node->b.get(), ray, next_leaf, b);
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

bool CsgSolid::Traced::intersect(const Ray& ray, ShapeHit& hit) const {
  std::vector<CsgBoundary> boundaries;
  uint32_t next_leaf = 0;
  csg_boundaries(root, ray, next_leaf, boundaries);
  for (const CsgBoundary& e : boundaries) {
    if (e.t <= ray.tmin) continue;
    if (e.t >= ray.tmax) return false;
    hit.t = e.t;
    hit.part = e.leaf;
    hit.flip = e.flip;
    return true;
  }
  return false;
}

glm::vec3 CsgSolid::Traced::normal_at(const glm::vec3& position, const ShapeHit& hit) const {
  const Sphere& leaf = leaves[hit.part];
  glm::vec3 n = (position - leaf.center) / leaf.radius;
  return hit.flip ? -n : n;
}

void CsgSolid::Traced::bounding_balls(std::vector<BoundingBall>& out) const {
  for (const Sphere& s : leaves) s.bounding_balls(out);
}

}  // namespace rvr
