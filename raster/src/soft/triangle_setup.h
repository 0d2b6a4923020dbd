// softraster's front end: vertices transformed and projected once each, triangles culled, clipped
// and set up for the tile rasterizer (edge functions in fixed point, the perspective-correct
// barycentric planes). The arithmetic is the one softraster has always used, so every image is
// the same bytes whichever path a triangle takes.
#pragma once

#include <stddef.h>

#include <algorithm>
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "soft/setup_triangle.h"

namespace rvr::soft {

// Guard-band clipping keeps screen coordinates within +-(2^15 + 2^14) pixels, i.e. 28-bit
// fixed point, so edge functions (products of 29-bit differences) never overflow int64.
constexpr double kGuardPixels = double(1 << 16);
constexpr int kMaxImageSide = 1 << 15;
static_assert(kMaxImageSide - 1 <= INT16_MAX, "SetupTriangle's pixel box holds any pixel index");

// A vertex in clip space, projected when it lies in front of the near plane.
struct ProjectedVertex {
  glm::dvec4 clip;
  double sx = 0, sy = 0;     // screen position, y down
  int64_t fx = 0, fy = 0;    // the same in fixed point (INT64_MIN: not finite)
  double inv_w = 0;          // 1 / clip.w
  uint32_t reject = 0;       // bit p: outside frustum plane p (all three: the triangle is culled)
  uint32_t clip_planes = 0;  // bit p: outside near or guard plane p (any: the triangle is clipped)
};

// The flags of a vertex on the discarded side of a user clip plane (a planar mirror's view keeps
// only what lies beyond the mirror): beside the frustum's reject bits 0-5 and the near and guard
// planes' clip bits 0-4 (kScalarOnly is bit 5).
constexpr uint32_t kUserPlaneReject = 1u << 6;
constexpr uint32_t kUserPlaneClip = 1u << 6;

// Whether a world point lies on the discarded side of the world plane `keep` (keep · (p, 1) < 0).
inline bool discarded_by(const glm::dvec4& keep, const glm::vec3& p) {
  return glm::dot(keep, glm::dvec4(glm::dvec3(p), 1.0)) < 0.0;
}

class TriangleSetup {
 public:
  // `keep`, when set, is a world plane: only the part of each triangle on its positive side is
  // drawn (clipped as the near plane is).
  TriangleSetup(int width, int height, const glm::dmat4& view_projection,
                const std::optional<glm::dvec4>& keep = std::nullopt);

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
  std::optional<glm::dvec4> keep_;       // the user plane in the world
  std::optional<glm::dvec4> keep_clip_;  // the same plane in clip space
  Polygon poly_, scratch_;
};

}  // namespace rvr::soft
