#include "rvr/hybrid/hybrid_renderer.h"

#include <chrono>

#include "rvr/raster/soft_rasterizer.h"
#include "rvr/raytrace/primary_visibility.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/shared/timer.h"

namespace rvr {

namespace {

using Clock = std::chrono::steady_clock;

bool starts_with(const std::string& s, const char* prefix) {
  return s.rfind(prefix, 0) == 0;
}

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
  auto t_zbuffer = Clock::now();
  Expected<RenderOutput> zbuffer = rasterizer_->render(scene, visibility_options);
  const double zbuffer_seconds = seconds_since(t_zbuffer);
  if (!zbuffer) return zbuffer.error();
  const FrameBuffers& ids = zbuffer->buffers;
  PrimaryVisibility visible{ids.width, ids.height, ids.object_id, ids.primitive_id};

  auto t_trace = Clock::now();
  RayTracer tracer;
  Expected<RenderOutput> out = tracer.render_visible(scene, options, geometry, visible);
  const double trace_seconds = seconds_since(t_trace);
  if (!out) return out;
  RenderOutput& o = out.value();
  o.stats["time.zbuffer"] = zbuffer_seconds;
  o.stats["time.trace"] = trace_seconds;
  for (const auto& [key, value] : zbuffer->stats) o.stats["zbuffer." + key] = value;
  for (const auto& [key, value] : zbuffer->info) o.info["zbuffer." + key] = value;
  o.info["zbuffer"] = rasterizer_->name();
  for (const std::string& w : zbuffer->warnings) {
    // The tracer draws what the z-buffer skipped (CSG) and takes every sample it did not
    // (softraster's single sample): only the z-buffer's other notes concern the image.
    if (starts_with(w, "csg objects have no z-buffer form") || starts_with(w, "softraster: "))
      continue;
    o.warnings.push_back("z-buffer: " + w);
  }
  size_t csg = 0;
  for (const Object& obj : scene.objects) csg += obj.type == ObjectType::Csg;
  if (csg > 0)
    o.warnings.push_back("csg objects (" + std::to_string(csg) +
                         ") have no z-buffer form: the tracer intersects them for every pixel");
  return out;
}

}  // namespace rvr
