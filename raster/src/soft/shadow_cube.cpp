#include "soft/shadow_cube.h"

#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <optional>

#include "shadow_plan.h"
#include "soft/csg_pass.h"

namespace rvr::soft {
namespace {

// The face d falls on, in cube_face_rotations() order: the major axis of d; ties go to the
// first (the faces' frusta overlap on their shared edges).
int cube_face(const glm::vec3& d) {
  glm::vec3 a = glm::abs(d);
  if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0f ? 0 : 1;
  if (a.y >= a.z) return d.y >= 0.0f ? 2 : 3;
  return d.z >= 0.0f ? 4 : 5;
}

}  // namespace

void ShadowCube::build(const DrawList& list, const glm::vec3& light, const ShadowSettings& settings,
                       DepthTarget& scratch, tbb::task_arena& arena, DrawResult& work) {
  size_ = settings.size;
  const int n = size_;
  const glm::dmat4 to_light = glm::translate(glm::dmat4(1.0), -glm::dvec3(light));
  for (int f = 0; f < 6; ++f) {
    arena.execute([&] { scratch.clear(); });
    const glm::dmat4 view = glm::dmat4(glm::mat4(cube_face_rotations()[size_t(f)])) * to_light;
    DrawResult r = draw_triangles(list, settings.projection * view, scratch, arena, nullptr);
    // CSG solids cast their shadows too, resolved as the camera's view resolves them.
    const CsgPassResult csg =
        draw_csg_objects(list, settings.projection * view, light, std::nullopt, scratch, arena);
    r.set_up += csg.drawn.set_up;
    r.counters.generated += csg.drawn.counters.generated;
    work.set_up += r.set_up;
    work.counters.generated += r.counters.generated;
    work.counters.blocks_rejected += r.counters.blocks_rejected;
    work.peak_chunk_bytes = std::max(work.peak_chunk_bytes, r.peak_chunk_bytes);
    // The view depth w of the texel centre's nearest surface to the distance along its ray:
    // in the face's eye space the centre's direction is (u, v, -1) (90 degrees: tan = NDC).
    std::vector<float>& d = distance_[size_t(f)];
    d.resize(size_t(n) * size_t(n));
    for (int y = 0; y < n; ++y) {
      const double v = 1.0 - (double(y) + 0.5) / double(n) * 2.0;
      for (int x = 0; x < n; ++x) {
        const size_t i = size_t(y) * size_t(n) + size_t(x);
        if (!scratch.covered(i)) {
          d[i] = std::numeric_limits<float>::max();
          continue;
        }
        const double u = (double(x) + 0.5) / double(n) * 2.0 - 1.0;
        d[i] = float(scratch.depth(i) * std::sqrt(1.0 + u * u + v * v));
      }
    }
  }
}

float ShadowCube::visibility(const glm::vec3& P, const glm::vec3& L,
                             const glm::vec3& geometric_normal,
                             const ShadowSettings& settings) const {
  const float texel = 2.0f / float(size_);  // a texel's largest extent in tan units
  glm::vec3 n = glm::normalize(geometric_normal);
  const float true_dist = glm::length(P - L);
  if (glm::dot(n, L - P) < 0.0f) n = -n;  // the side of the surface the light is on
  // Normal offset: look up from P moved off its own surface, towards the light, by one texel's
  // footprint at this distance, so grazing surfaces stop reading their own neighbouring texels.
  const glm::vec3 d = P + n * (texel * true_dist) - L;
  const float dist = glm::length(d);
  const int face = cube_face(d);
  const glm::vec3 e =
      cube_face_rotations()[size_t(face)] * d;  // eye space of the face, looking down -z
  const glm::vec2 uv = glm::vec2(e.x, e.y) / std::max(-e.z, 1e-30f) * 0.5f + 0.5f;
  // Row 0 of a face as drawn is its top (uv.y = 1).
  const int tx = std::clamp(int(std::floor(uv.x * float(size_))), 0, size_ - 1);
  const int ty = std::clamp(int(std::floor((1.0f - uv.y) * float(size_))), 0, size_ - 1);
  // Slope-scaled term: the map holds the distance at its texel centre, up to ~0.7 texel away
  // from the lookup direction; on a surface at angle theta to the light ray that changes the
  // distance by about dist * 0.7 * texel * tan(theta). Capped so grazing surfaces keep shadows.
  const float cos_theta = std::abs(glm::dot(n, d / std::max(dist, 1e-30f)));
  const float tan_theta = std::min(
      std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta)) / std::max(cos_theta, 1e-6f), 8.0f);
  const float bias = settings.bias + 0.75f * texel * dist * tan_theta;
  const std::vector<float>& map = distance_[size_t(face)];
  auto lit = [&](int x, int y) {
    return dist - bias <= map[size_t(y) * size_t(size_) + size_t(x)] ? 1.0f : 0.0f;
  };
  if (!settings.pcf) return lit(tx, ty);
  float sum = 0.0f;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      sum += lit(std::clamp(tx + dx, 0, size_ - 1), std::clamp(ty + dy, 0, size_ - 1));
  return sum / 9.0f;
}

}  // namespace rvr::soft
