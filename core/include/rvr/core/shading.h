// The one shading equation of docs/design.md (local part). The GLSL in raster/ mirrors it line for
// line; keep the two in step.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <vector>

#include "rvr/core/scene.h"

namespace rvr {

// Orients the shading normal to face the viewer (two-sided lighting). The decision uses the
// geometric normal, so an interpolated normal cannot flip on its own near a silhouette.
inline glm::vec3 face_viewer(const glm::vec3& shading_normal, const glm::vec3& geometric_normal,
                             const glm::vec3& to_viewer) {
  return glm::dot(geometric_normal, to_viewer) < 0.0f ? -shading_normal : shading_normal;
}

// x^s for x >= 0 with 0^0 = 1, spelled out because GLSL leaves pow(0, 0) undefined.
inline float specular_power(float x, float s) {
  if (x <= 0.0f) return s == 0.0f ? 1.0f : 0.0f;
  return std::pow(x, s);
}

// Adds the light of samples [first, end) to `colour`: sum_l vis_l * (diffuse*max(0,N.Ld) +
// specular*max(0,N.H)^shininess) * I_l / |L_l - P|^2, in sample order. A renderer that has the
// visibility of only some samples at a time (shadow maps in batches) adds them batch by batch
// and gets the same sum, term for term, as one pass over all of them.
template <class Visibility>
void add_light_samples(const Material& m, const glm::vec3& P, const glm::vec3& N,
                       const glm::vec3& V, const std::vector<LightSample>& lights, size_t first,
                       size_t end, Visibility&& visibility, glm::vec3& colour) {
  for (size_t i = first; i < end; ++i) {
    glm::vec3 to_light = lights[i].position - P;
    float dist2 = glm::dot(to_light, to_light);
    if (!(dist2 > 0.0f)) continue;
    glm::vec3 Ld = to_light / std::sqrt(dist2);
    float n_dot_l = std::max(0.0f, glm::dot(N, Ld));
    glm::vec3 H = glm::normalize(Ld + V);
    float n_dot_h = std::max(0.0f, glm::dot(N, H));
    glm::vec3 brdf = m.diffuse * n_dot_l + m.specular * specular_power(n_dot_h, m.shininess);
    if (brdf == glm::vec3(0.0f)) continue;
    float vis = visibility(i, P, lights[i].position);
    colour += vis * brdf * lights[i].intensity / dist2;
  }
}

// The part of the equation without lights.
inline glm::vec3 shade_base(const Material& m, const glm::vec3& ambient) {
  return m.emission + ambient * m.diffuse;
}

// local = emission + ambient*diffuse + sum_l vis_l * (diffuse*max(0,N.Ld) +
//         specular*max(0,N.H)^shininess) * I_l / |L_l - P|^2
// N: unit normal facing the viewer; V: unit vector towards the viewer.
// visibility(sample_index, P, L) returns vis_l in [0, 1] (1 in local mode).
template <class Visibility>
glm::vec3 shade_local(const Material& m, const glm::vec3& P, const glm::vec3& N, const glm::vec3& V,
                      const glm::vec3& ambient, const std::vector<LightSample>& lights,
                      Visibility&& visibility) {
  glm::vec3 colour = shade_base(m, ambient);
  add_light_samples(m, P, N, V, lights, 0, lights.size(), visibility, colour);
  return colour;
}

inline glm::vec3 shade_local(const Material& m, const glm::vec3& P, const glm::vec3& N,
                             const glm::vec3& V, const glm::vec3& ambient,
                             const std::vector<LightSample>& lights) {
  return shade_local(m, P, N, V, ambient, lights,
                     [](size_t, const glm::vec3&, const glm::vec3&) { return 1.0f; });
}

}  // namespace rvr
