// What the tracer and the hybrids prepare alike: the tracer's geometry (its acceleration
// structure) built once for the frames to come, each frame then drawn by `Loop` over it
// (RayTracer, or HybridRenderer whose z-buffer pass is part of every frame).
#pragma once

#include <memory>
#include <utility>

#include "rvr/core/framebuffers.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/renderers/prepared_renderer.h"

namespace rvr {

template <class Loop>
class PreparedOverGeometry : public PreparedRenderer {
 public:
  template <class... LoopArgs>
  PreparedOverGeometry(const Scene& scene, const RenderOptions& options, AccelKind accel,
                       LoopArgs&&... loop_args)
      : scene_(scene),
        options_(options),
        loop_(std::forward<LoopArgs>(loop_args)...),
        geometry_(scene, options.spheres, options.sphere_segments, accel, options.triangle_test,
                  options.isa) {}
  // The frame, then the scene's exposure (as for every renderer of the registry).
  Expected<RenderOutput> render() override {
    Expected<RenderOutput> out = loop_.render(scene_, options_, geometry_);
    if (out.ok()) apply_exposure(out->buffers, scene_.image.exposure);
    return out;
  }

  // `accel` answers the queries (the options' for raytrace and the hybrids, Embree for embree);
  // the chapter's triangle test runs on the binary tree, as RayTracer::render does it, since
  // the SIMD kernels test triangles with Moller-Trumbore only.
  template <class... LoopArgs>
  static Expected<std::unique_ptr<PreparedRenderer>> prepare(const Scene& scene,
                                                             const RenderOptions& options,
                                                             AccelKind accel,
                                                             LoopArgs&&... loop_args) {
    if (options.triangle_test == TriangleTest::Chapter && accel == AccelKind::Bvh)
      accel = AccelKind::Bvh2;
    auto prepared = std::make_unique<PreparedOverGeometry>(scene, options, accel,
                                                           std::forward<LoopArgs>(loop_args)...);
    const TraceGeometry& g = prepared->geometry_;
    if (!g.error().empty()) return Error{g.error(), g.error_kind()};
    return std::unique_ptr<PreparedRenderer>(std::move(prepared));
  }

 private:
  const Scene& scene_;
  const RenderOptions options_;
  Loop loop_;
  TraceGeometry geometry_;
};

}  // namespace rvr
