#include "prepared_tracer.h"

#include "rvr/raytrace/ray_tracer.h"
#include "rvr/raytrace/trace_geometry.h"

namespace rvr {

namespace {

class PreparedTracer : public PreparedRenderer {
 public:
  PreparedTracer(const Scene& scene, const RenderOptions& options, AccelKind accel)
      : scene_(scene),
        options_(options),
        geometry_(scene, options.spheres, options.sphere_segments, accel, options.triangle_test,
                  options.isa) {}
  const TraceGeometry& geometry() const { return geometry_; }
  Expected<RenderOutput> render() override { return tracer_.render(scene_, options_, geometry_); }

 private:
  const Scene& scene_;
  const RenderOptions options_;
  RayTracer tracer_;
  TraceGeometry geometry_;
};

}  // namespace

Expected<std::unique_ptr<PreparedRenderer>> prepare_tracer(const Scene& scene,
                                                           const RenderOptions& options,
                                                           AccelKind accel) {
  // As RayTracer::render: the SIMD kernels test triangles with Moller-Trumbore only, so the
  // chapter's test runs on the binary tree.
  if (options.triangle_test == TriangleTest::Chapter && accel == AccelKind::Bvh)
    accel = AccelKind::Bvh2;
  auto prepared = std::make_unique<PreparedTracer>(scene, options, accel);
  const TraceGeometry& g = prepared->geometry();
  if (!g.error().empty()) return Error{g.error(), g.error_kind()};
  return std::unique_ptr<PreparedRenderer>(std::move(prepared));
}

}  // namespace rvr
