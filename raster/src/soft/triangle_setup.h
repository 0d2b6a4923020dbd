// softraster's front end: vertices transformed and projected once each, triangles culled, clipped
// and set up for the tile rasterizer (edge functions in fixed point, the perspective-correct
// barycentric planes). The arithmetic is the one softraster has always used, so every image is
// the same bytes whichever path a triangle takes.
#pragma once

#include <stddef.h>

#include <algorithm>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "soft/setup_triangle.h"

namespace rvr::soft {

// Guard-band clipping keeps screen coordinates within +-(2^15 + 2^14) pixels, i.e. 28-bit
// fixed point, so edge functions (products of 29-bit differences) never overflow int64.
constexpr double kGuardPixels = double(1 << 16);
constexpr int kMaxImageSide = 1 << 15;

// A vertex in clip space, projected when it lies in front of the near plane.
struct ProjectedVertex {
  glm::dvec4 clip;
  double sx = 0, sy = 0;     // screen position, y down
  int64_t fx = 0, fy = 0;    // the same in fixed point (INT64_MIN: not finite)
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
           uint32_t object, uint32_t primitive, SetupTriangles& out, size_t& clipped);

 private:
  struct ClipVertex {
    glm::dvec4 c;  // clip space
    glm::dvec3 b;  // barycentric in the original triangle
  };
  using Polygon = std::vector<ClipVertex>;
  static void clip_polygon(const Polygon& in, const glm::dvec4& plane, Polygon& out);
  void clip_and_emit(const ProjectedVertex* v[3], uint32_t object, uint32_t primitive,
                     SetupTriangles& out);
  // One screen triangle: vertices' screen and fixed-point positions and f_j = b_j / w.
  void emit(const double sx[3], const double sy[3], const int64_t fx[3], const int64_t fy[3],
            const double f[3][3], const double w[3], uint32_t object, uint32_t primitive,
            SetupTriangles& out) const;

  int width_, height_;
  glm::dmat4 view_projection_;
  glm::dvec4 frustum_[6];
  glm::dvec4 clip_planes_[5];
  Polygon poly_, scratch_;
};

}  // namespace rvr::soft
