// Mip chains, GL's texture filters and the levels of detail of docs/design.md ("Textures").
#include "rvr/core/texture.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "rvr/core/check.h"
#include "rvr/core/scene.h"

namespace rvr {

glm::vec2 UvTransform::apply(glm::vec2 uv) const {
  if (identity()) return uv;
  const glm::vec2 s(uv.x * scale.x, (1.0f - uv.y) * scale.y);
  const float c = std::cos(rotation), n = std::sin(rotation);
  const glm::vec2 r(c * s.x - n * s.y, n * s.x + c * s.y);
  return {r.x + offset.x, 1.0f - (r.y + offset.y)};
}

namespace {

// The texels of level k that texel i of level k+1 averages along one axis: [2i, 2i + 2), and
// the last one also takes the odd texel left over ([2i, 2i + 3)).
std::pair<int, int> reduced_span(int i, int size, int reduced) {
  RVR_DCHECK(i >= 0 && i < reduced && reduced == std::max(1, size / 2), "texel ", i,
             " of a level of ", reduced, " halving ", size);
  int first = std::min(2 * i, size - 1);
  int end = std::min(2 * i + 2, size);
  if (i == reduced - 1) end = size;
  return {first, end};
}

TextureLevel reduce(const TextureLevel& from) {
  TextureLevel to;
  to.width = std::max(1, from.width / 2);
  to.height = std::max(1, from.height / 2);
  to.texels.resize(size_t(to.width) * size_t(to.height));
  for (int y = 0; y < to.height; ++y) {
    auto [y0, y1] = reduced_span(y, from.height, to.height);
    for (int x = 0; x < to.width; ++x) {
      auto [x0, x1] = reduced_span(x, from.width, to.width);
      glm::vec3 sum(0.0f);
      for (int j = y0; j < y1; ++j)
        for (int i = x0; i < x1; ++i) sum += from.at(i, j);
      to.texels[size_t(y) * size_t(to.width) + size_t(x)] = sum / float((y1 - y0) * (x1 - x0));
    }
  }
  return to;
}

// A texel index wrapped into [0, size) as GL wraps the integer coordinates of LINEAR.
int wrap_index(int i, int size, TextureWrap wrap) {
  RVR_DCHECK(size > 0, "a texture side holds texels: ", size);
  switch (wrap) {
    case TextureWrap::ClampToEdge:
      return std::clamp(i, 0, size - 1);
    case TextureWrap::MirroredRepeat: {
      int period = 2 * size;
      int m = ((i % period) + period) % period;
      return m < size ? m : period - 1 - m;
    }
    case TextureWrap::Repeat:
      break;
  }
  return ((i % size) + size) % size;
}

// GL's LINEAR along one axis: the lower texel index and the weight of the upper one. The
// coordinate is reduced to one period first (Repeat: fract; mirrored: two periods) so that huge
// coordinates keep their fraction; clamping needs no reduction.
std::pair<int, float> linear_taps(float coord, int size, TextureWrap wrap) {
  if (!std::isfinite(coord)) coord = 0.0f;
  if (wrap == TextureWrap::Repeat) coord -= std::floor(coord);
  if (wrap == TextureWrap::MirroredRepeat) coord -= 2.0f * std::floor(coord * 0.5f);
  if (wrap == TextureWrap::ClampToEdge) coord = std::clamp(coord, 0.0f, 1.0f);
  const float p = coord * float(size) - 0.5f;
  const float base = std::floor(p);
  return {int(base), p - base};
}

}  // namespace

MipChain build_mip_chain(TextureLevel level0) {
  RVR_CHECK(level0.width > 0 && level0.height > 0 &&
                level0.texels.size() == size_t(level0.width) * size_t(level0.height),
            "a texture's level 0 holds width x height texels: ", level0.width, "x", level0.height,
            ", ", level0.texels.size());
  MipChain chain;
  chain.levels.push_back(std::move(level0));
  while (chain.levels.back().width > 1 || chain.levels.back().height > 1)
    chain.levels.push_back(reduce(chain.levels.back()));
  RVR_CHECK(chain.levels.size() <= 32, "a mip chain halves a side of at most 2^31 texels");
  return chain;
}

glm::vec3 sample_bilinear(const TextureLevel& level, TextureWrap wrap_u, TextureWrap wrap_v,
                          glm::vec2 uv) {
  RVR_DCHECK(level.width > 0 && level.height > 0, "a texture level has texels");
  auto [x, fx] = linear_taps(uv.x, level.width, wrap_u);
  auto [y, fy] = linear_taps(uv.y, level.height, wrap_v);
  const int x0 = wrap_index(x, level.width, wrap_u), x1 = wrap_index(x + 1, level.width, wrap_u);
  const int y0 = wrap_index(y, level.height, wrap_v), y1 = wrap_index(y + 1, level.height, wrap_v);
  const glm::vec3 bottom = glm::mix(level.at(x0, y0), level.at(x1, y0), fx);
  const glm::vec3 top = glm::mix(level.at(x0, y1), level.at(x1, y1), fx);
  return glm::mix(bottom, top, fy);
}

glm::vec3 sample_trilinear(const MipChain& mips, TextureWrap wrap_u, TextureWrap wrap_v,
                           glm::vec2 uv, float lod) {
  RVR_DCHECK(!mips.levels.empty(), "a texture sampled has a level 0");
  if (std::isnan(lod)) lod = 0.0f;
  lod = std::clamp(lod, 0.0f, mips.max_lod());
  const int level = int(std::floor(lod));
  const float f = lod - float(level);
  const glm::vec3 a = sample_bilinear(mips.levels[size_t(level)], wrap_u, wrap_v, uv);
  if (f == 0.0f) return a;
  const glm::vec3 b = sample_bilinear(mips.levels[size_t(level) + 1], wrap_u, wrap_v, uv);
  return glm::mix(a, b, f);
}

float lod_from_derivatives(glm::vec2 duv_dx, glm::vec2 duv_dy, int width, int height) {
  const glm::vec2 size{float(width), float(height)};
  const float rho = std::max(glm::length(duv_dx * size), glm::length(duv_dy * size));
  return rho > 0.0f ? std::log2(rho) : -std::numeric_limits<float>::infinity();
}

float triangle_lod_constant(float world_area, float uv_area, int width, int height) {
  const float texel_area = float(width) * float(height) * std::abs(uv_area);
  if (!(world_area > 0.0f) || !(texel_area > 0.0f)) return -std::numeric_limits<float>::infinity();
  return 0.5f * std::log2(texel_area / world_area);
}

float lod_from_cone(float triangle_constant, float cone_width, float cos_theta) {
  const float w = std::abs(cone_width) / std::max(std::abs(cos_theta), 1e-6f);
  return w > 0.0f ? triangle_constant + std::log2(w) : -std::numeric_limits<float>::infinity();
}

float primary_cone_spread(float fov_y_radians, int image_height) {
  return std::atan(2.0f * std::tan(0.5f * fov_y_radians) / float(image_height));
}

}  // namespace rvr
