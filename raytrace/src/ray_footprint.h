// How wide a ray is where it meets a surface, for the texture's level of detail there
// (RenderOptions::texture_lod), carried from the camera through reflections and refractions:
//  - a ray cone (Akenine-Moller et al., "Texture Level of Detail Strategies for Real-Time Ray
//    Tracing", Ray Tracing Gems ch. 20, 2019): a width and a spread angle; the width grows by
//    spread x distance; at a hit lambda = delta + log2(width / |cos theta|) (lod_from_cone);
//  - ray differentials (Igehy, "Tracing Ray Differentials", 1999): the derivatives of the ray's
//    origin and direction with respect to the pixel's x and y, transferred to the hit point,
//    turned into derivatives of the texture coordinates, and those into GL's level of detail
//    (lod_from_derivatives).
// Surfaces are treated as locally flat (triangles are; dN = 0): a reflection or refraction
// changes neither the cone's spread (the chapter's curvature term is 0) nor adds a normal
// derivative to the differentials.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>

#include "rvr/core/camera.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/texture.h"

namespace rvr {

// A ray's footprint: its cone and its differentials with respect to pixel x and y. Direction
// derivatives are of the ray's direction as the ray carries it (a primary ray's has forward
// component 1; a secondary ray's is unit length), so that t means the same in both.
struct RayFootprint {
  float cone_width = 0.0f;   // at the ray's origin
  float cone_spread = 0.0f;  // radians: the width grows by cone_spread per unit distance
  glm::vec3 dO_dx{0.0f}, dO_dy{0.0f};
  glm::vec3 dD_dx{0.0f}, dD_dy{0.0f};
};

// The footprint at a hit: the cone's width there, the hit point's differentials (on the
// surface's plane) and those of the unit incoming direction (for the rays that leave).
struct HitFootprint {
  float cone_width = 0.0f;
  float cone_spread = 0.0f;
  glm::vec3 dP_dx{0.0f}, dP_dy{0.0f};
  glm::vec3 dd_dx{0.0f}, dd_dy{0.0f};  // of normalize(direction)
};

// A primary ray's footprint: a cone of width 0 at the eye with primary_cone_spread (eq. 30);
// the direction forward + right * column + up * row differentiated along the pixel grid
// (camera_ray_direction): d/dx = right * 2 tan(fov_y / 2) aspect / width, d/dy = -up * 2
// tan(fov_y / 2) / height (y grows downwards).
RayFootprint primary_footprint(const CameraFrame& frame);

// The footprint of a ray origin + t * direction where it meets a surface of unit normal N at t.
// Igehy's transfer: dP = (dO + t dD) - ((dO + t dD) . N / (D . N)) D.
HitFootprint footprint_at_hit(const RayFootprint& ray, const glm::vec3& direction, float t,
                              const glm::vec3& N);

// The footprints of the rays leaving a hit: the cone carries on with its width and spread; the
// differentials start at dP and turn by the derivative of the mirror formula
// R = d - 2 (d . N) N, or of the refraction T = eta d + (eta cos_i - sqrt(k)) N with
// cos_i = -d . N and k = 1 - eta^2 (1 - cos_i^2) (d unit, N the normal the ray was bent by).
RayFootprint reflected_footprint(const HitFootprint& hit, const glm::vec3& N);
RayFootprint refracted_footprint(const HitFootprint& hit, const glm::vec3& d, const glm::vec3& N,
                                 float eta);

// The texture's level of detail at a hit on `triangle` of `mesh` (material m, texture of
// width x height texels), `direction` the ray's, N the triangle's unit geometric normal.
// Cones: triangle_lod_constant of the triangle's world and uv areas, and lod_from_cone with
// the width at the hit and cos theta = N . normalize(direction). Differentials: dP split into
// barycentric derivatives on the triangle's edges, those into uv derivatives by the uvs (after
// the material's uv_transform), then lod_from_derivatives. None: 0.
float texture_lod_at_hit(TextureLod kind, const HitFootprint& hit, const glm::vec3& direction,
                         const glm::vec3& N, const TriangleMesh& mesh, const Material& m,
                         uint32_t triangle, int width, int height);

}  // namespace rvr
