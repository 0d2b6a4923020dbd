#include "rvr/hybrid/hybrid_renderer.h"

#include <stddef.h>

#include <chrono>
#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "approximated_pixels.h"
#include "hybrid_counters.h"
#include "primary_visibility.h"
#include "rvr/core/check.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/progress.h"
#include "rvr/core/timer.h"
#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raster/soft_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"
#include "zbuffer_hits.h"

namespace rvr {

namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

HybridRenderer::HybridRenderer(ZBufferKind zbuffer, GlBackend gl) : zbuffer_(zbuffer), gl_(gl) {}

HybridRenderer::~HybridRenderer() = default;

Expected<RenderOutput> HybridRenderer::render(const Scene& scene, const RenderOptions& requested) {
  RenderOptions options = requested;
  // As RayTracer::render: the SIMD kernels test triangles with Moller-Trumbore only.
  if (options.triangle_test == TriangleTest::Chapter && options.accel == AccelKind::Bvh)
    options.accel = AccelKind::Bvh2;
  if (scene.image.width <= 0 || scene.image.height <= 0)
    return bad_input("image size must be positive");
  auto t_build = Clock::now();
  if (ProgressSink* p = options.progress) p->begin("build");
  TraceGeometry geometry(scene, options.spheres, options.sphere_segments, options.accel,
                         options.triangle_test, options.isa);
  double build_seconds = seconds_since(t_build);
  if (!geometry.error().empty()) return Error{geometry.error(), geometry.error_kind()};
  Expected<RenderOutput> out = render(scene, options, geometry);
  if (out.ok()) out.value().stats["time.build"] = build_seconds;
  return out;
}

Expected<RenderOutput> HybridRenderer::render(const Scene& scene, const RenderOptions& options,
                                              const TraceGeometry& geometry) {
  if (!rasterizer_) {
    if (zbuffer_ == ZBufferKind::Gl)
      rasterizer_ = std::make_unique<GlRasterizer>(gl_);
    else
      rasterizer_ = std::make_unique<SoftRasterizer>();
  }
  // The z-buffer pass writes ids and depth only: the visibility buffer.
  RenderOptions visibility_options = options;
  visibility_options.mode = RenderMode::Visibility;
  visibility_options.cost_aov = false;  // the cost AOV is the tracer's
  // Primary hits take the z-buffer's level of detail (its own screen-space derivatives).
  visibility_options.visibility_lod = true;
  // Only the ids are read (ZBufferHits rebuilds each hit from them): softraster writes no other
  // buffer.
  visibility_options.visibility_ids_only = true;
  // The shapes the z-buffer would draw as polygons inside them (spheres, discs) or combine from
  // their leaves (CSG) are not drawn: ZBufferHits intersects them wherever they may appear, so
  // their polygons would only hide the surfaces behind them and cost a pass of triangles.
  visibility_options.zbuffer_left_out = geometry.approximated_objects();
  auto t_zbuffer = Clock::now();
  Expected<RenderOutput> zbuffer = rasterizer_->render(scene, visibility_options);
  const double zbuffer_seconds = seconds_since(t_zbuffer);
  if (!zbuffer) return zbuffer.error();
  if (is_cancelled(options.progress)) return cancelled_error();  // between z-buffer and trace
  const FrameBuffers& ids = zbuffer->buffers;
  RVR_CHECK(ids.width == scene.image.width && ids.height == scene.image.height &&
                ids.object_id.size() == ids.pixel_count() &&
                ids.primitive_id.size() == ids.pixel_count(),
            "the z-buffer pass fills an id per pixel of the scene's frame");
  const PrimaryVisibility visible{ids.width, ids.height, ids.object_id, ids.primitive_id, ids.lod};

  // The tracer shades the hits the z-buffer's ids give (ZBufferHits), the centre's colour only.
  auto t_trace = Clock::now();
  RayTracer tracer;
  const std::vector<uint8_t> approximated = approximated_pixels(scene, geometry);
  const ZBufferHits centre(scene, geometry, visible, approximated);
  Expected<RenderOutput> out = tracer.render(scene, options, geometry, centre);
  double trace_seconds = seconds_since(t_trace);
  double zbuffer_pass_seconds = zbuffer_seconds;
  if (!out) return out;
  RenderOutput& o = out.value();
  centre.counters().add_to(o.stats);

  // Several samples per pixel: one more z-buffer pass per sample (the accumulation buffer),
  // each drawn through that sample's place in the pixel and lens point, its hits rebuilt and
  // shaded by the tracer and summed; the centre pass gives the AOVs, as in the tracer.
  const int spp = scene.image.samples_per_pixel;
  if (spp > 1 && options.mode != RenderMode::Visibility) {
    FrameBuffers& fb = o.buffers;
    std::vector<glm::vec3> sum(fb.pixel_count(), glm::vec3(0.0f));
    for (int k = 0; k < spp; ++k) {
      if (is_cancelled(options.progress)) return cancelled_error();  // per accumulation pass
      visibility_options.image_sample =
          image_sample(scene.camera, options.seed, k, spp, options.mode == RenderMode::Full);
      auto t_pass = Clock::now();
      Expected<RenderOutput> pass = rasterizer_->render(scene, visibility_options);
      zbuffer_pass_seconds += seconds_since(t_pass);
      if (!pass) return pass.error();
      const FrameBuffers& pass_ids = pass->buffers;
      RVR_CHECK(pass_ids.width == ids.width && pass_ids.height == ids.height &&
                    pass_ids.object_id.size() == ids.pixel_count() &&
                    pass_ids.primitive_id.size() == ids.pixel_count(),
                "every sample's z-buffer pass has the centre pass's frame");
      const ZBufferHits sample_hits(
          scene, geometry,
          PrimaryVisibility{pass_ids.width, pass_ids.height, pass_ids.object_id,
                            pass_ids.primitive_id, pass_ids.lod});
      t_pass = Clock::now();
      auto pass_stats = tracer.add_samples(scene, options, geometry, sample_hits, k, sum);
      trace_seconds += seconds_since(t_pass);
      if (!pass_stats) return pass_stats.error();
      for (const auto& [key, value] : pass_stats.value()) o.stats[key] += value;
      sample_hits.counters().add_to(o.stats);
    }
    // The tracer's own average: the same float operations in the same order.
    for (size_t i = 0; i < sum.size(); ++i) fb.colour[i] = sum[i] / float(spp);
    o.stats["hybrid.zbuffer_passes"] = double(spp + 1);
  } else {
    o.stats["hybrid.zbuffer_passes"] = 1.0;
  }
  o.stats["time.zbuffer"] = zbuffer_pass_seconds;
  o.stats["time.trace"] = trace_seconds;
  for (const auto& [key, value] : zbuffer->stats) o.stats["zbuffer." + key] = value;
  for (const auto& [key, value] : zbuffer->info) o.info["zbuffer." + key] = value;
  o.info["zbuffer"] = rasterizer_->name();
  for (const std::string& w : zbuffer->warnings) {
    // The tracer takes every sample the z-buffer did not (softraster's single sample): only
    // the z-buffer's other notes concern the image.
    if (w.ends_with("multisampling is not implemented, rendered 1")) continue;
    o.warnings.push_back("z-buffer: " + w);
  }
  size_t csg = 0;
  for (const Object& obj : scene.objects) csg += obj.type == ObjectType::Csg;
  if (csg > 0)
    o.warnings.push_back("csg objects (" + std::to_string(csg) +
                         "): the tracer intersects them wherever they may appear, "
                         "the z-buffer does not draw them");
  return out;
}

}  // namespace rvr
