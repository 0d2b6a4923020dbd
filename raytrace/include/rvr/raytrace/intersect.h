// Ray-triangle intersection: the test of chapter 20 plus Moller-Trumbore (the analytic shapes
// own theirs: rvr/core/shapes/). Each returns the hit parameter t in (ray.tmin, ray.tmax) and the
// cheap data the closest-hit search needs; surface data is computed once, later.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <utility>

#include "rvr/core/ray.h"

namespace rvr {

// A triangle precomputed as v0, e1 = v1 - v0, e2 = v2 - v0 (as Embree stores them).
struct TrianglePrecomputed {
  glm::vec3 v0, e1, e2;
};

inline TrianglePrecomputed precompute_triangle(const glm::vec3& a, const glm::vec3& b,
                                               const glm::vec3& c) {
  return {a, b - a, c - a};
}

// Barycentric hit: P = v0 + u e1 + v e2.
struct TriangleHit {
  float t, u, v;
};

// Barycentric slack for edge tests: rounding can put a point on a shared edge outside both
// triangles (a crack that shows what lies behind); a hair of overlap closes it. Both hits
// then have the same t.
constexpr float kBarycentricSlack = 1e-6f;

// Moller-Trumbore in double precision, for hits close to an edge: with the ray origin far from
// a small triangle, s = o - v0 is large and the float barycentrics lose about
// |o - v0| / |edge| ulps (2e-5 seen on a tessellated sphere at 7 units), enough to open cracks.
inline bool intersect_triangle_mt_double(const Ray& ray, const TrianglePrecomputed& tri,
                                         TriangleHit& hit) {
  glm::dvec3 d(ray.dir), e1(tri.e1), e2(tri.e2);
  glm::dvec3 p = glm::cross(d, e2);
  double det = glm::dot(e1, p);
  if (det == 0.0) return false;
  double inv_det = 1.0 / det;
  glm::dvec3 s = glm::dvec3(ray.origin) - glm::dvec3(tri.v0);
  double u = glm::dot(s, p) * inv_det;
  if (u < -kBarycentricSlack || u > 1.0 + kBarycentricSlack) return false;
  glm::dvec3 q = glm::cross(s, e1);
  double v = glm::dot(d, q) * inv_det;
  if (v < -kBarycentricSlack || u + v > 1.0 + kBarycentricSlack) return false;
  float t = float(glm::dot(e2, q) * inv_det);
  if (!(t > ray.tmin && t < ray.tmax)) return false;
  hit = {t, float(u), float(v)};
  return true;
}

// Moller-Trumbore: solves o + t d = v0 + u e1 + v e2 by Cramer's rule. Edges and vertices are
// inside (u, v >= 0, u + v <= 1, with kBarycentricSlack). The float pass rejects what is
// clearly outside and accepts what is clearly inside; within kEdgeBand of an edge the
// barycentrics are recomputed in double, so a shared edge never leaks. The pass compares
// U = u det and V = v det against det (signs flipped when det < 0), so the division is done
// only for a hit. The SIMD kernels (src/kernels/wide_kernels.inl) do exactly these operations
// in this order, so they find the same hits to the bit.
constexpr float kEdgeBand = 1e-3f;

inline bool intersect_triangle_mt(const Ray& ray, const TrianglePrecomputed& tri,
                                  TriangleHit& hit) {
  glm::vec3 p = glm::cross(ray.dir, tri.e2);
  float det = glm::dot(tri.e1, p);
  if (det == 0.0f) return false;  // ray parallel to the triangle's plane (or degenerate)
  const float sign = std::signbit(det) ? -1.0f : 1.0f;
  const float abs_det = det * sign;
  glm::vec3 s = ray.origin - tri.v0;
  float su = glm::dot(s, p);
  glm::vec3 q = glm::cross(s, tri.e1);
  float sv = glm::dot(ray.dir, q);
  float U = su * sign, V = sv * sign, UV = U + V;
  float outer_lo = -kEdgeBand * abs_det, outer_hi = (1.0f + kEdgeBand) * abs_det;
  if (U < outer_lo || U > outer_hi || V < outer_lo || UV > outer_hi) return false;
  if (U < kEdgeBand * abs_det || V < kEdgeBand * abs_det || UV > (1.0f - kEdgeBand) * abs_det)
    return intersect_triangle_mt_double(ray, tri, hit);
  float inv_det = 1.0f / det;
  float t = glm::dot(tri.e2, q) * inv_det;
  if (!(t > ray.tmin && t < ray.tmax)) return false;
  hit = {t, su * inv_det, sv * inv_det};
  return true;
}

// The chapter's test: hit the triangle's plane, then check that the point lies on the inner
// side of all three edges (the three sub-triangles P-v0-v1, P-v1-v2, P-v2-v0 have the same
// orientation as the triangle).
inline bool intersect_triangle_chapter(const Ray& ray, const TrianglePrecomputed& tri,
                                       TriangleHit& hit) {
  glm::vec3 n = glm::cross(tri.e1, tri.e2);
  float denom = glm::dot(n, ray.dir);
  if (denom == 0.0f) return false;  // parallel to the plane
  float t = glm::dot(n, tri.v0 - ray.origin) / denom;
  if (!(t > ray.tmin && t < ray.tmax)) return false;
  glm::vec3 p = ray.origin + t * ray.dir - tri.v0;  // relative to v0
  float n2 = glm::dot(n, n);
  float slack = -kBarycentricSlack * n2;
  // Edge v0->v1: orientation of (v0, v1, P) is v * |n|^2.
  float w_v = glm::dot(glm::cross(tri.e1, p), n);
  if (w_v < slack) return false;
  // Edge v2->v0: orientation of (v2, v0, P) is u * |n|^2.
  float w_u = glm::dot(glm::cross(p, tri.e2), n);
  if (w_u < slack) return false;
  // Edge v1->v2: orientation of (v1, v2, P) is (1 - u - v) * |n|^2.
  float w_w = glm::dot(glm::cross(tri.e2 - tri.e1, p - tri.e1), n);
  if (w_w < slack) return false;
  hit = {t, w_u / n2, w_v / n2};
  return true;
}

}  // namespace rvr
