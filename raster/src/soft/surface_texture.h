// softraster's textured and vertex-coloured surfaces: the base colour at a pixel from the
// perspective-correct barycentrics the z-buffer kept, and the texture's level of detail from the
// exact screen-space derivatives of the texture coordinates. Over a triangle, q_j = b_j / w is
// affine in the pixel position (x, y), so uv(x, y) = sum_j q_j uv_j / sum_j q_j is a ratio of
// two affine functions, and its derivatives along x and y are exact closed forms; the level of
// detail is GL's formula (lod_from_derivatives) on them.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "rvr/core/scene.h"

namespace rvr::soft {

// The base colour at a pixel and the level of detail it was sampled at (NaN: not textured).
struct SurfaceSample {
  glm::vec3 base;
  float lod;
};

// One triangle's texture coordinates as rational functions of the pixel position:
// q_j(x, y) = q0[j] + qx[j] * x + qy[j] * y, uv = sum_j q_j uv[j] / sum_j q_j.
struct UvPlanes {
  double q0[3], qx[3], qy[3];
  glm::dvec2 uv[3];
  bool valid = false;  // false: the triangle's plane passes through the eye (seen edge-on)
};

// The planes of the triangle with world corners p[3] and texture coordinates uv[3] drawn through
// view_projection onto a width x height viewport (row 0 at the top, pixel centres at +0.5).
UvPlanes uv_planes(const glm::dmat4& view_projection, int width, int height,
                   const glm::vec3 (&p)[3], const glm::vec2 (&uv)[3]);

// d(uv)/dx and d(uv)/dy at the pixel position (x, y).
void uv_derivatives(const UvPlanes& planes, double x, double y, glm::dvec2& duv_dx,
                    glm::dvec2& duv_dy);

// The planes of the last triangle asked for, kept by each thread: consecutive pixels mostly show
// the same triangle, whose planes are then not made again.
struct PlanesCache {
  uint32_t object = 0xFFFFFFFFu, primitive = 0xFFFFFFFFu;
  UvPlanes planes;
};

// Which objects of the scene (indexed as scene.objects, which the draw list follows) vary in
// colour, and their base colour per pixel.
class SurfaceColours {
 public:
  SurfaceColours(const Scene& scene, const glm::dmat4& view_projection, int width, int height);

  bool any() const { return any_; }            // some object varies in colour
  bool textured() const { return textured_; }  // some object is textured (a lod buffer)
  bool varies(uint32_t object) const { return varies_[object] != 0; }

  // The level of detail of `object`'s triangle `primitive` at pixel (x, y): GL's formula on the
  // exact derivatives; NaN when the object is not textured.
  float lod(uint32_t object, const Material& material, uint32_t primitive, int x, int y,
            PlanesCache& cache) const;

  // The base colour of `object`'s triangle `primitive` at pixel (x, y), whose perspective-correct
  // barycentrics are b, with `material` (the object's).
  SurfaceSample at(uint32_t object, const Material& material, uint32_t primitive,
                   const glm::vec3& b, int x, int y, PlanesCache& cache) const;

 private:
  const Scene& scene_;
  glm::dmat4 view_projection_;
  int width_, height_;
  std::vector<uint8_t> varies_, textured_objects_;
  bool any_ = false, textured_ = false;
};

}  // namespace rvr::soft
