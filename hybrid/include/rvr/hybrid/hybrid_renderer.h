// The hybrid loop order: "for each triangle, for each pixel" for what the eye sees (a z-buffer
// pass writing object and primitive ids, a visibility buffer), then "for each pixel" for the
// rest: the tracer rebuilds each pixel's exact hit from those ids and shades it with its own
// full-mode code (shadow rays, area-light samples, mirror and refraction rays).
#pragma once

#include <memory>
#include <string>

#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/raytrace/trace_geometry.h"

namespace rvr {

// Which z-buffer resolves primary visibility.
enum class ZBufferKind {
  Gl,    // GlRasterizer: "hybrid"
  Soft,  // SoftRasterizer: "hybrid_soft"
};

class HybridRenderer : public Renderer {
 public:
  explicit HybridRenderer(ZBufferKind zbuffer, GlBackend gl = GlBackend::Default);
  ~HybridRenderer() override;

  std::string name() const override {
    return zbuffer_ == ZBufferKind::Gl ? "hybrid" : "hybrid_soft";
  }
  // Builds the tracer's geometry (time.build), then renders a frame over it.
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options) override;
  // A frame over geometry built beforehand from the same scene and options (benchmarks).
  // Stats: time.zbuffer (the visibility pass), time.trace (rebuilt hits, shading, every traced
  // ray), the tracer's counters and hybrid.*; the z-buffer's own under "zbuffer.".
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options,
                                const TraceGeometry& geometry);

 private:
  ZBufferKind zbuffer_;
  GlBackend gl_;
  // Kept between frames, as a GL context keeps its framebuffer.
  std::unique_ptr<Renderer> rasterizer_;
};

}  // namespace rvr
