#include "ray_footprint.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "rvr/core/check.h"
#include "rvr/core/surface_colour.h"

namespace rvr {

RayFootprint primary_footprint(const CameraFrame& frame) {
  RayFootprint f;
  f.cone_width = 0.0f;
  f.cone_spread = std::atan(2.0f * frame.tan_half_fov_y / float(frame.height));
  f.dD_dx = frame.right * (2.0f * frame.tan_half_fov_y * frame.aspect / float(frame.width));
  f.dD_dy = frame.up * (-2.0f * frame.tan_half_fov_y / float(frame.height));
  return f;
}

namespace {

// Igehy's eq. 10: the derivative of the hit point, kept on the surface's plane.
glm::vec3 transfer(const glm::vec3& dO, const glm::vec3& dD, const glm::vec3& D, float t,
                   const glm::vec3& N) {
  const glm::vec3 moved = dO + t * dD;
  return moved - (glm::dot(moved, N) / glm::dot(D, N)) * D;
}

// The derivative of normalize(D) for a change dD of D.
glm::vec3 unit_derivative(const glm::vec3& D, const glm::vec3& dD) {
  const float length = glm::length(D);
  const glm::vec3 d = D / length;
  return (dD - glm::dot(d, dD) * d) / length;
}

}  // namespace

HitFootprint footprint_at_hit(const RayFootprint& ray, const glm::vec3& direction, float t,
                              const glm::vec3& N) {
  RVR_DCHECK(t >= 0.0f, "a hit lies ahead of its ray: t = ", t);
  HitFootprint h;
  h.cone_width = ray.cone_width + ray.cone_spread * t * glm::length(direction);
  h.cone_spread = ray.cone_spread;
  h.dP_dx = transfer(ray.dO_dx, ray.dD_dx, direction, t, N);
  h.dP_dy = transfer(ray.dO_dy, ray.dD_dy, direction, t, N);
  h.dd_dx = unit_derivative(direction, ray.dD_dx);
  h.dd_dy = unit_derivative(direction, ray.dD_dy);
  return h;
}

RayFootprint reflected_footprint(const HitFootprint& hit, const glm::vec3& N) {
  RayFootprint r;
  r.cone_width = hit.cone_width;
  r.cone_spread = hit.cone_spread;
  r.dO_dx = hit.dP_dx;
  r.dO_dy = hit.dP_dy;
  r.dD_dx = hit.dd_dx - 2.0f * glm::dot(hit.dd_dx, N) * N;
  r.dD_dy = hit.dd_dy - 2.0f * glm::dot(hit.dd_dy, N) * N;
  return r;
}

RayFootprint refracted_footprint(const HitFootprint& hit, const glm::vec3& d, const glm::vec3& N,
                                 float eta) {
  const float cos_i = -glm::dot(d, N);
  const float root_k = std::sqrt(std::max(1.0f - eta * eta * (1.0f - cos_i * cos_i), 0.0f));
  // d(eta cos_i - sqrt(k)) = (eta - eta^2 cos_i / sqrt(k)) dcos_i, with dcos_i = -dd . N.
  const float bend = root_k > 0.0f ? eta - eta * eta * cos_i / root_k : 0.0f;
  RayFootprint r;
  r.cone_width = hit.cone_width;
  r.cone_spread = hit.cone_spread;
  r.dO_dx = hit.dP_dx;
  r.dO_dy = hit.dP_dy;
  r.dD_dx = eta * hit.dd_dx - bend * glm::dot(hit.dd_dx, N) * N;
  r.dD_dy = eta * hit.dd_dy - bend * glm::dot(hit.dd_dy, N) * N;
  return r;
}

namespace {

// The uv derivative for a point derivative dP on the triangle's plane: dP = db1 e1 + db2 e2
// solved by the cross products with the (unnormalised) normal n = e1 x e2.
glm::vec2 uv_derivative(const glm::vec3& dP, const glm::vec3& e1, const glm::vec3& e2,
                        const glm::vec3& n, const glm::vec2& duv1, const glm::vec2& duv2) {
  const float n2 = glm::dot(n, n);
  const float db1 = glm::dot(glm::cross(dP, e2), n) / n2;
  const float db2 = glm::dot(glm::cross(e1, dP), n) / n2;
  return db1 * duv1 + db2 * duv2;
}

float differentials_lod(const HitFootprint& hit, const TriangleMesh& mesh, const Material& m,
                        uint32_t triangle, int width, int height) {
  const glm::uvec3 c = mesh.triangles[triangle];
  const glm::vec3 e1 = mesh.positions[c.y] - mesh.positions[c.x];
  const glm::vec3 e2 = mesh.positions[c.z] - mesh.positions[c.x];
  const glm::vec3 n = glm::cross(e1, e2);
  if (!(glm::dot(n, n) > 0.0f)) return 0.0f;  // degenerate: no plane to differentiate on
  const glm::vec2 uv0 = m.uv_transform.apply(mesh.uvs[c.x]);
  const glm::vec2 duv1 = m.uv_transform.apply(mesh.uvs[c.y]) - uv0;
  const glm::vec2 duv2 = m.uv_transform.apply(mesh.uvs[c.z]) - uv0;
  return lod_from_derivatives(uv_derivative(hit.dP_dx, e1, e2, n, duv1, duv2),
                              uv_derivative(hit.dP_dy, e1, e2, n, duv1, duv2), width, height);
}

}  // namespace

float texture_lod_at_hit(TextureLod kind, const HitFootprint& hit, const glm::vec3& direction,
                         const glm::vec3& N, const TriangleMesh& mesh, const Material& m,
                         uint32_t triangle, int width, int height) {
  switch (kind) {
    case TextureLod::Cones: {
      const float delta = triangle_lod_constant(triangle_world_area(mesh, triangle),
                                                triangle_uv_area(mesh, m, triangle), width, height);
      return lod_from_cone(delta, hit.cone_width, glm::dot(N, glm::normalize(direction)));
    }
    case TextureLod::Differentials:
      return differentials_lod(hit, mesh, m, triangle, width, height);
    case TextureLod::None:
      break;
  }
  return 0.0f;
}

}  // namespace rvr
