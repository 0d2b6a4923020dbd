// softraster's front end: vertices transformed and projected once each, triangles culled, clipped
// and set up for the tile rasterizer (edge functions in fixed point, the perspective-correct
// barycentric planes). The arithmetic is the one softraster has always used, so every image is
// the same bytes whichever path a triangle takes.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "rvr/shared/scene.h"

namespace rvr::soft {

// Sub-pixel precision of the edge functions: finer than GL's usual 8 bits, so that snapping
// an edge-on sliver (a sphere's silhouette) rarely makes it cover a centre it does not.
constexpr int kSubBits = 12;
constexpr int64_t kSub = int64_t(1) << kSubBits;
// Guard-band clipping keeps screen coordinates within +-(2^15 + 2^14) pixels, i.e. 28-bit
// fixed point, so edge functions (products of 29-bit differences) never overflow int64.
constexpr double kGuardPixels = double(1 << 16);
constexpr int kMaxImageSide = 1 << 15;

// A screen-space triangle after clipping. One input triangle gives up to a few of these.
struct SetupTriangle {
  std::array<int64_t, 3> x, y;   // fixed point, oriented so the edge functions are >= 0 inside
  std::array<bool, 3> top_left;  // edge i runs from vertex i to vertex i+1
  // q_j(p) = q0[j] + qa[j]*(px - ox) + qb[j]*(py - oy) = (barycentric j of the ORIGINAL
  // triangle) / w: linear in screen space, so sum_j q_j = 1/w = 1/view depth, and q_j/sum is
  // the perspective-correct barycentric. From the unsnapped vertices, in double: P must be
  // exact where 1/|L - P|^2 is steep (surfaces next to a light).
  std::array<double, 3> q0, qa, qb;
  double ox = 0, oy = 0;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // pixel bounding box, inclusive, on screen
  // No fragment is nearer than this (view depth): the hi-z test's bound (see min_depth_bound).
  double min_depth = 0;
  uint32_t object = 0, primitive = 0;

  double inv_w(double px, double py, std::array<double, 3>& q) const {
    double s = 0;
    for (int j = 0; j < 3; ++j) {
      // Clamped: a sliver may cover a centre just outside itself (snapping); it is then seen
      // at its nearest edge point instead of extrapolating depth.
      q[j] = std::max(0.0, q0[j] + qa[j] * (px - ox) + qb[j] * (py - oy));
      s += q[j];
    }
    return s;
  }
};

// A vertex in clip space, projected when it lies in front of the near plane.
struct ProjectedVertex {
  glm::dvec4 clip;
  double sx = 0, sy = 0;     // screen position, y down
  int64_t fx = 0, fy = 0;    // the same in fixed point
  double inv_w = 0;          // 1 / clip.w
  uint32_t reject = 0;       // bit p: outside frustum plane p (all three: the triangle is culled)
  uint32_t clip_planes = 0;  // bit p: outside near or guard plane p (any: the triangle is clipped)
};

class TriangleSetup {
 public:
  TriangleSetup(int width, int height, const glm::dmat4& view_projection);

  ProjectedVertex project(const glm::vec3& p) const;

  // Culls, clips and sets up one input triangle; appends what covers a pixel centre's bounding
  // box to `out`. Counts clipped or culled input triangles in `clipped`.
  void add(const ProjectedVertex& a, const ProjectedVertex& b, const ProjectedVertex& c,
           uint32_t object, uint32_t primitive, std::vector<SetupTriangle>& out, size_t& clipped);

 private:
  struct ClipVertex {
    glm::dvec4 c;  // clip space
    glm::dvec3 b;  // barycentric in the original triangle
  };
  using Polygon = std::vector<ClipVertex>;
  static void clip_polygon(const Polygon& in, const glm::dvec4& plane, Polygon& out);
  void clip_and_emit(const ProjectedVertex* v[3], uint32_t object, uint32_t primitive,
                     std::vector<SetupTriangle>& out);
  // One screen triangle: vertices' screen and fixed-point positions and f_j = b_j / w.
  void emit(const double sx[3], const double sy[3], const int64_t fx[3], const int64_t fy[3],
            const double f[3][3], const double w[3], uint32_t object, uint32_t primitive,
            std::vector<SetupTriangle>& out) const;

  int width_, height_;
  glm::dmat4 view_projection_;
  glm::dvec4 frustum_[6];
  glm::dvec4 clip_planes_[5];
  Polygon poly_, scratch_;
};

}  // namespace rvr::soft
