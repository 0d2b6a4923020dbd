// Depth of field as a post-process, the z-buffer's cheap answer to the thin lens: one pinhole
// pass (multisampled where the GL is asked to) blurred, each pixel spread over its circle of
// confusion from its depth. Its known errors, which the accumulation buffer (accumulation_buffer.h)
// does not have: a defocused object does not reveal what lies behind it (the pinhole saw only its
// front), its blur stops at the depth discontinuity that hides a sharper surface, and the disk
// is taken in pixels from the pixel's one depth.
#pragma once

#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr {

// The largest circle of confusion the blur gathers, in pixels; wider ones are clamped to it.
inline constexpr int kMaxBlurRadius = 32;

// Whether a z-buffer render blurs its colour for depth of field: full mode, a lens, several
// samples per pixel (with one the tracer too keeps the pinhole) and --zbuffer-dof blur.
bool blurs_depth_of_field(const Scene& scene, const RenderOptions& options);

// The radius, in pixels of an image `height` pixels tall, of the disk over which the camera's
// thin lens spreads a point at view depth `depth`: aperture_radius * |1/focus - 1/depth| in
// tangent units (the lens point's offset seen from that depth, measured at the focus plane),
// times the pixels per tangent unit, height / (2 tan(fov_y / 2)). Infinite depth (the
// background) gives the limit aperture_radius / focus.
float circle_of_confusion_pixels(const Camera& camera, int height, float depth);

// The gather form of scattering every pixel's colour uniformly over its circle of confusion:
// pixel p takes the mean of the pixels q whose disk covers it, each weighted by 1 / (its disk's
// area, at least one pixel), so that a surface of one depth keeps its brightness. A q behind p
// covers p only within p's own radius, so a blurred background does not spread over a sharper
// surface in front. Circles are clamped to kMaxBlurRadius (returns the largest before the
// clamp). Deterministic: each pixel sums its window in one order, on `threads` threads (0: all).
float blur_depth_of_field(const Camera& camera, FrameBuffers& fb, int threads);

// A z-buffer's render finished the blur way when blurs_depth_of_field: its colour blurred, the
// stats time.dof_blur and dof.blur_radius, and a warning that says what the blur cannot show.
void add_depth_of_field_blur(const Scene& scene, const RenderOptions& options, RenderOutput& out);

}  // namespace rvr
