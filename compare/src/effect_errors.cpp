#include "rvr/compare/effect_errors.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <memory>

#include "dimmed_backdrop.h"
#include "rvr/core/effect_answer.h"
#include "ssim.h"

namespace rvr {

namespace {

// Bit k: the effect kEffectKeys[k].
enum EffectBit : uint8_t { kReflection = 1, kRefraction = 2, kLens = 4, kCsg = 8 };

// The effects acting at a pixel whose primary surface is object `id` (kNoId: background).
uint8_t effects_at(const Scene& scene, RenderMode mode, bool lens, uint32_t id) {
  uint8_t bits = lens ? kLens : 0;
  if (id == kNoId || id >= scene.objects.size()) return bits;
  const Object& o = scene.objects[id];
  if (o.type == ObjectType::Csg) bits |= kCsg;
  if (mode == RenderMode::Full && o.material < scene.materials.size()) {
    const Material& m = scene.materials[o.material];
    if (m.mirror > 0.0f) bits |= kReflection;
    if (m.transparency > 0.0f) bits |= kRefraction;
  }
  return bits;
}

// Every pixel's effects (EffectBit), by its primary surface in `mask_from`.
std::vector<uint8_t> effect_bits(const Scene& scene, RenderMode mode,
                                 const FrameBuffers& mask_from) {
  const bool lens = mode == RenderMode::Full && scene.camera.aperture_radius > 0.0f &&
                    scene.image.samples_per_pixel > 1;
  std::vector<uint8_t> bits(mask_from.object_id.size());
  for (size_t i = 0; i < bits.size(); ++i)
    bits[i] = effects_at(scene, mode, lens, mask_from.object_id[i]);
  return bits;
}

// A colour error summed over pixels, then finished into rmse, PSNR and mean SSIM.
struct ErrorSum {
  size_t pixels = 0;
  double sq = 0.0, max_abs = 0.0, ssim = 0.0;
  void add(const FrameBuffers& a, const FrameBuffers& b, const std::vector<double>& ssim_at,
           size_t i) {
    ++pixels;
    ssim += ssim_at[i];
    for (int c = 0; c < 3; ++c) {
      double d = std::fabs(double(a.colour[i][c]) - double(b.colour[i][c]));
      if (std::isnan(d)) d = 1.0;  // as the whole image's colour error counts a NaN
      sq += d * d;
      max_abs = std::max(max_abs, d);
    }
  }
  double rmse() const { return pixels > 0 ? std::sqrt(sq / (3.0 * double(pixels))) : 0.0; }
  double psnr_db() const {
    const double r = rmse();
    return r > 0.0 ? 20.0 * std::log10(1.0 / r) : std::numeric_limits<double>::infinity();
  }
  double mean_ssim() const { return pixels > 0 ? ssim / double(pixels) : 1.0; }
};

// The SSIM map of a's and b's luminance (ssim.h).
std::vector<double> luminance_ssim(const FrameBuffers& a, const FrameBuffers& b) {
  const size_t n = a.pixel_count();
  std::vector<float> ya(n), yb(n);
  for (size_t i = 0; i < n; ++i) {
    ya[i] = luminance(a.colour[i]);
    yb[i] = luminance(b.colour[i]);
  }
  return ssim_map(ya, yb, a.width, a.height);
}

}  // namespace

const FrameBuffers* answering_frame(const FrameBuffers& a, const FrameBuffers& b) {
  if (!a.answer.empty() && a.answer.size() == a.pixel_count()) return &a;
  if (!b.answer.empty() && b.answer.size() == b.pixel_count()) return &b;
  return nullptr;
}

std::vector<EffectError> effect_errors(const Scene& scene, RenderMode mode,
                                       const FrameBuffers& mask_from, const FrameBuffers& a,
                                       const FrameBuffers& b) {
  const size_t n = mask_from.pixel_count();
  if (mask_from.object_id.size() != n || a.colour.size() != n || b.colour.size() != n) return {};
  const std::vector<uint8_t> bits = effect_bits(scene, mode, mask_from);
  const FrameBuffers* answered = answering_frame(a, b);
  if (answered && answered->pixel_count() != n) answered = nullptr;
  const bool any = std::any_of(bits.begin(), bits.end(), [](uint8_t b) { return b != 0; });
  // The SSIM window needs both frames laid out as the mask's.
  if (!any || a.width != mask_from.width || b.width != mask_from.width || a.pixel_count() != n ||
      b.pixel_count() != n)
    return {};
  const std::vector<double> ssim_at = luminance_ssim(a, b);
  std::vector<EffectError> errors;
  for (size_t k = 0; k < std::size(kEffectKeys); ++k) {
    ErrorSum all;
    std::vector<ErrorSum> by_answer(kEffectAnswers);
    for (size_t i = 0; i < n; ++i) {
      if (!(bits[i] & (1u << k))) continue;
      all.add(a, b, ssim_at, i);
      if (answered)
        by_answer[std::min<size_t>(answered->answer[i], kEffectAnswers - 1)].add(a, b, ssim_at, i);
    }
    if (all.pixels == 0) continue;
    EffectError e;
    e.effect = kEffectKeys[k].name;
    e.pixels = all.pixels;
    e.rmse = all.rmse();
    e.psnr_db = all.psnr_db();
    e.max_abs = all.max_abs;
    e.ssim = all.mean_ssim();
    for (size_t c = 0; c < kEffectAnswers; ++c) {
      const ErrorSum& s = by_answer[c];
      if (s.pixels == 0) continue;
      e.answers.push_back({effect_answer_name(EffectAnswer(c)), s.pixels, s.rmse(), s.psnr_db(),
                           s.max_abs, s.mean_ssim()});
    }
    errors.push_back(e);
  }
  return errors;
}

Image effect_mask_image(const Scene& scene, RenderMode mode, const FrameBuffers& mask_from) {
  const std::vector<uint8_t> bits = effect_bits(scene, mode, mask_from);
  return overlay_on_dimmed(mask_from, [&](size_t i) -> const float* {
    if (i >= bits.size()) return nullptr;
    // The lens last: it touches every pixel, and the others would not show through it.
    for (int k : {0, 1, 3, 2})
      if (bits[i] & (1u << k)) return kEffectKeys[k].rgb;
    return nullptr;
  });
}

static_assert(std::size(kAnswerColours) == kEffectAnswers, "a colour per answer");

Image answer_image(const FrameBuffers& answered) {
  return overlay_on_dimmed(answered, [&](size_t i) -> const float* {
    const size_t answer = i < answered.answer.size() ? answered.answer[i] : 0;
    return answer > 0 && answer < kEffectAnswers ? kAnswerColours[answer] : nullptr;
  });
}

}  // namespace rvr
