#include "shadow_plan.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "rvr/core/check.h"

namespace rvr {
namespace {

// Memory: one cube is 6 * size^2 * 4 bytes (24 MiB at 1024), so the samples go in batches that
// fit this; each batch draws its cubes and then adds its samples' light. 64 MiB hold 2 samples
// at 1024^2.
constexpr size_t kShadowBatchBytes = size_t(64) << 20;
// Work: every face is cleared and rasterised, so the texels per frame grow with the sample
// count. Above this budget (16 samples at 1024^2 fit) the side shrinks, with a warning, but
// not below kShadowMinSize unless the requested side is smaller.
constexpr double kShadowTexelBudget = 6.0 * 16.0 * 1024.0 * 1024.0 * 1.25;
constexpr int kShadowMinSize = 64;

}  // namespace

Expected<ShadowMapPlan> plan_shadow_maps(const RenderOptions& options,
                                         const std::vector<LightSample>& samples, int max_side,
                                         size_t max_batch, const glm::vec3& lo, const glm::vec3& hi,
                                         bool any_geometry, std::vector<std::string>& warnings) {
  RVR_DCHECK(!samples.empty() && max_side > 0 && max_batch > 0,
             "a plan is made for at least one light sample, on a device that holds a cube");
  // The render option table's ranges (rvr/core/render_option_table.h) hold these.
  RVR_DCHECK(options.shadow_map_size >= 1 && options.shadow_bias >= 0.0f &&
                 std::isfinite(options.shadow_bias),
             "shadow map options outside the render option table's ranges");
  ShadowMapPlan plan;
  plan.size = std::min(options.shadow_map_size, max_side);
  const double texels = 6.0 * double(samples.size()) * double(plan.size) * double(plan.size);
  if (texels > kShadowTexelBudget) {
    const int fit = int(std::sqrt(kShadowTexelBudget / (6.0 * double(samples.size()))));
    plan.size = std::max(std::min(plan.size, kShadowMinSize), fit);
  }
  if (plan.size < options.shadow_map_size)
    warnings.push_back(
        fmt::format("shadow maps of {} texels per side for {} light samples ({} "
                    "requested)",
                    plan.size, samples.size(), options.shadow_map_size));
  const size_t per_sample = 6 * size_t(plan.size) * size_t(plan.size) * sizeof(float);
  plan.batch =
      std::min(std::clamp<size_t>(kShadowBatchBytes / per_sample, 1, samples.size()), max_batch);
  // How far the scene reaches from the samples (at least 1e-3; 1 for an empty scene). Near and
  // far only clip: the maps hold distances, so a near plane far below any feature size costs
  // no precision.
  float reach = 0.0f;
  for (const LightSample& ls : samples)
    reach = std::max(reach,
                     glm::length(glm::max(glm::abs(ls.position - lo), glm::abs(ls.position - hi))));
  if (!any_geometry) reach = 1.0f;
  reach = std::max(reach, 1e-3f);
  plan.near_plane = 1e-6f * reach;
  plan.far_plane = 2.0f * reach;
  return plan;
}

const std::array<glm::mat3, 6>& cube_face_rotations() {
  static const std::array<glm::mat3, 6> rotations = [] {
    const std::array<glm::vec3, 6> directions = {glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0),
                                                 glm::vec3(0, 1, 0), glm::vec3(0, -1, 0),
                                                 glm::vec3(0, 0, 1), glm::vec3(0, 0, -1)};
    std::array<glm::mat3, 6> r;
    for (size_t f = 0; f < 6; ++f) {
      const glm::vec3 up =
          std::abs(directions[f].y) > 0.5f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
      r[f] = glm::mat3(glm::lookAt(glm::vec3(0.0f), directions[f], up));
    }
    return r;
  }();
  return rotations;
}

}  // namespace rvr
