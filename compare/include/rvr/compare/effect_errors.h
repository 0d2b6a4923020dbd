// The error of a comparison where each of the chapter's effects acts: the pixels whose colour
// depends on a reflection, a refraction, the lens or a CSG solid, and the colour error inside
// each set. A whole-image PSNR dilutes an effect that covers a few per cent of the frame; these
// figures do not.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/image_codec/image_io.h"

namespace rvr {

// The colour error over the pixels of one effect's mask that one z-buffer technique answered
// (EffectAnswer, rvr/core/effect_answer.h): where each approximation's known failure lies.
struct AnswerError {
  std::string answer;  // effect_answer_name: "cube_map_reflection", "ssr_off_screen", ...
  size_t pixels = 0;
  double rmse = 0.0;
  double psnr_db = 0.0;  // +inf when identical
  double max_abs = 0.0;
  double ssim = 1.0;  // the mean of the whole image's SSIM map over these pixels
};

// The colour error (linear RGB, peak 1, as ComparisonMetrics::colour) over the pixels one
// effect touches.
struct EffectError {
  std::string effect;  // "reflection", "refraction", "lens", "csg"
  size_t pixels = 0;   // the effect's mask
  double rmse = 0.0;
  double psnr_db = 0.0;  // +inf when identical
  double max_abs = 0.0;
  // The mean over the mask of the whole image's SSIM map (ComparisonMetrics::colour.ssim is
  // its mean over every pixel): the perceptual error where the effect acts, with its context
  // (the window reaches 5 pixels past the mask).
  double ssim = 1.0;
  // When a or b holds a z-buffer's answers (FrameBuffers::answer, a's first): the mask split by
  // answer, in EffectAnswer's order, answers no pixel of the mask has left out. Empty else.
  std::vector<AnswerError> answers;
};

// The effects `mask_from` shows (a frame of the scene: the tracer's, whose primary surfaces the
// masks are read from) and the colour error of a against b inside each mask, in the order
// reflection, refraction, lens, csg; an effect no pixel shows is left out. The masks, by the
// primary surface at each pixel of `mask_from`:
// - reflection: a material with mirror > 0; refraction: transparency > 0 (full mode only:
//   the other modes shade neither);
// - lens: every pixel, in full mode with aperture_radius > 0 and samples_per_pixel > 1;
// - csg: a CSG object (any mode).
// A pixel whose colour depends on an effect only after another bounce (a mirror seen through
// glass) counts under the first surface's effects alone. The frames must have one size.
std::vector<EffectError> effect_errors(const Scene& scene, RenderMode mode,
                                       const FrameBuffers& mask_from, const FrameBuffers& a,
                                       const FrameBuffers& b);

// The frame of a and b that holds a z-buffer's answers (a's first), or nullptr.
const FrameBuffers* answering_frame(const FrameBuffers& a, const FrameBuffers& b);

// answers.png: each pixel of `answered` where a technique answered an effect in its answer's
// colour (kAnswerColours), over a dimmed grey version of its colour elsewhere.
Image answer_image(const FrameBuffers& answered);

// The colours answers.png shows each EffectAnswer in (display-referred), in its order.
inline constexpr float kAnswerColours[][3] = {
    {0.0f, 0.0f, 0.0f},  // none: not drawn
    {0.2f, 0.5f, 1.0f},  // reflected_view
    {0.3f, 0.9f, 0.9f},  // layer_view
    {1.0f, 0.6f, 0.1f},  // cube_map_reflection
    {0.9f, 0.9f, 0.2f},  // cube_map_refraction
    {1.0f, 0.2f, 0.2f},  // first_interface_only
    {0.3f, 0.9f, 0.3f},  // ssr_hit
    {1.0f, 0.2f, 1.0f},  // ssr_off_screen
    {0.6f, 0.2f, 0.9f},  // ssr_hidden
    {0.6f, 0.6f, 0.6f},  // ssr_background
    {1.0f, 1.0f, 1.0f},  // left_out
    {0.5f, 0.3f, 0.1f},  // at_limit
};

// The effects in effect_errors' order, their names and the colours effects.png shows them in.
struct EffectKey {
  const char* name;
  float rgb[3];  // display-referred
};
inline constexpr EffectKey kEffectKeys[] = {{"reflection", {0.2f, 0.6f, 1.0f}},
                                            {"refraction", {0.3f, 0.9f, 0.4f}},
                                            {"lens", {1.0f, 0.8f, 0.2f}},
                                            {"csg", {1.0f, 0.3f, 0.8f}}};

// effects.png: each pixel of `mask_from` in the colour of the first effect that touches it (in
// kEffectKeys' order; the lens, which touches every pixel, shows only where nothing else
// does), over a dimmed grey version of its colour elsewhere.
Image effect_mask_image(const Scene& scene, RenderMode mode, const FrameBuffers& mask_from);

}  // namespace rvr
