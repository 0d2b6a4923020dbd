#include "soft/surface_texture.h"

#include <stddef.h>

#include <cmath>
#include <limits>
#include <memory>

#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/surface_colour.h"
#include "rvr/core/texture.h"

namespace rvr::soft {

UvPlanes uv_planes(const glm::dmat4& view_projection, int width, int height,
                   const glm::vec3 (&p)[3], const glm::vec2 (&uv)[3]) {
  // A point of the triangle with barycentrics b has clip coordinates (X, Y, W) = M b, the
  // columns of M being the corners' (x, y, w). Its normalized device coordinates n = (X/W, Y/W, 1)
  // give M^-1 n = b / W = q: q is linear in n, hence affine in the pixel position.
  glm::dmat3 m;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec4 c = view_projection * glm::dvec4(glm::dvec3(p[k]), 1.0);
    m[k] = glm::dvec3(c.x, c.y, c.w);
  }
  UvPlanes planes;
  for (int k = 0; k < 3; ++k) planes.uv[k] = glm::dvec2(uv[k]);
  const double det = glm::determinant(m);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return planes;
  const glm::dmat3 inv = glm::inverse(m);
  // Pixel position to device coordinates: n_x = 2 x / width - 1, n_y = 1 - 2 y / height.
  const double ax = 2.0 / width, ay = -2.0 / height;
  for (int j = 0; j < 3; ++j) {
    const double rx = inv[0][j], ry = inv[1][j], r1 = inv[2][j];  // row j of M^-1
    planes.qx[j] = rx * ax;
    planes.qy[j] = ry * ay;
    planes.q0[j] = r1 - rx + ry;
  }
  planes.valid = true;
  return planes;
}

void uv_derivatives(const UvPlanes& planes, double x, double y, glm::dvec2& duv_dx,
                    glm::dvec2& duv_dy) {
  double q[3], sum = 0.0;
  for (int j = 0; j < 3; ++j) {
    q[j] = planes.q0[j] + planes.qx[j] * x + planes.qy[j] * y;
    sum += q[j];
  }
  glm::dvec2 uv(0.0);
  for (int j = 0; j < 3; ++j) uv += q[j] * planes.uv[j];
  uv /= sum;
  // d(N / D) = (dN - (N / D) dD) / D, with N = sum q_j uv_j and D = sum q_j.
  duv_dx = glm::dvec2(0.0);
  duv_dy = glm::dvec2(0.0);
  for (int j = 0; j < 3; ++j) {
    duv_dx += planes.qx[j] * (planes.uv[j] - uv);
    duv_dy += planes.qy[j] * (planes.uv[j] - uv);
  }
  duv_dx /= sum;
  duv_dy /= sum;
}

SurfaceColours::SurfaceColours(const Scene& scene, const glm::dmat4& view_projection, int width,
                               int height)
    : scene_(scene),
      view_projection_(view_projection),
      width_(width),
      height_(height),
      varies_(scene.objects.size()),
      textured_objects_(scene.objects.size()) {
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    varies_[i] = varies_in_colour(scene, scene.objects[i]);
    textured_objects_[i] = rvr::textured(scene, scene.objects[i]);
    any_ = any_ || varies_[i];
    textured_ = textured_ || textured_objects_[i];
  }
}

float SurfaceColours::lod(uint32_t object, const Material& material, uint32_t primitive, int x,
                          int y, PlanesCache& cache) const {
  if (!textured_objects_[object]) return std::numeric_limits<float>::quiet_NaN();
  if (cache.object != object || cache.primitive != primitive) {
    const TriangleMesh& mesh = scene_.objects[object].mesh;
    const glm::uvec3 t = mesh.triangles[primitive];
    const glm::vec3 p[3] = {mesh.positions[t.x], mesh.positions[t.y], mesh.positions[t.z]};
    const glm::vec2 uv[3] = {material.uv_transform.apply(mesh.uvs[t.x]),
                             material.uv_transform.apply(mesh.uvs[t.y]),
                             material.uv_transform.apply(mesh.uvs[t.z])};
    cache.planes = uv_planes(view_projection_, width_, height_, p, uv);
    cache.object = object;
    cache.primitive = primitive;
  }
  if (!cache.planes.valid) return std::numeric_limits<float>::infinity();  // edge-on: coarsest
  glm::dvec2 dx, dy;
  uv_derivatives(cache.planes, double(x) + 0.5, double(y) + 0.5, dx, dy);
  const MipChain& mips = *scene_.textures[size_t(material.texture)].mips;
  return lod_from_derivatives(glm::vec2(dx), glm::vec2(dy), mips.width(), mips.height());
}

SurfaceSample SurfaceColours::at(uint32_t object, const Material& material, uint32_t primitive,
                                 const glm::vec3& b, int x, int y, PlanesCache& cache) const {
  const float level = lod(object, material, primitive, x, y, cache);
  return {base_colour(scene_, scene_.objects[object], material, primitive, b.y, b.z, level), level};
}

}  // namespace rvr::soft
