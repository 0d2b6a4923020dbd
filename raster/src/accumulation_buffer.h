// Supersampling and depth of field the z-buffer way (Haeberli & Akeley 1990, the accumulation
// buffer): one pass per sample of a pixel, each drawn through that sample's place in the pixel
// and lens point, the passes' colours averaged. The samples are the tracer's own
// (rvr/core/image_sample.h), so sample k of a z-buffer sees what the tracer's sample k sees, up
// to rasterization, and both average them in the same order. Both z-buffers (GlRasterizer,
// SoftRasterizer) render their passes through this one loop.
#pragma once

#include <functional>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr {

// Whether a render takes its colour from an accumulation buffer: several samples per pixel in a
// shaded mode (local or full; full mode adds the lens when the camera has an aperture), not
// already one pass of one (options.image_sample set), and not a lens whose depth of field is a
// blur (--zbuffer-dof blur: one pinhole pass, blurred).
bool accumulates(const Scene& scene, const RenderOptions& options);

// Renders one pass with the options given (image_sample set for a sample's pass, unset for the
// centre pass that gives the AOVs).
using ZBufferPass = std::function<Expected<RenderOutput>(const RenderOptions&)>;

// The centre pass (ids, depth, normal, cost and its counters, as one sample at every pixel
// centre, as the tracer's AOVs) and then one pass per sample, whose colours are averaged into
// the centre pass's colour. Adds the stats zbuffer.accumulation_passes and
// time.accumulation, and the sample passes' warnings not already given.
Expected<RenderOutput> render_accumulated(const Scene& scene, const RenderOptions& options,
                                          const ZBufferPass& pass);

}  // namespace rvr
