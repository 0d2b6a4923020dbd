#include "prepared_hybrid.h"

namespace rvr {

namespace {

class PreparedHybrid : public PreparedRenderer {
 public:
  PreparedHybrid(const Scene& scene, const RenderOptions& options, AccelKind accel,
                 ZBufferKind zbuffer, GlBackend gl)
      : scene_(scene),
        options_(options),
        hybrid_(zbuffer, gl),
        geometry_(scene, options.spheres, options.sphere_segments, accel, options.triangle_test,
                  options.isa) {}
  const TraceGeometry& geometry() const { return geometry_; }
  Expected<RenderOutput> render() override { return hybrid_.render(scene_, options_, geometry_); }

 private:
  const Scene& scene_;
  const RenderOptions options_;
  HybridRenderer hybrid_;
  TraceGeometry geometry_;
};

}  // namespace

Expected<std::unique_ptr<PreparedRenderer>> prepare_hybrid(const Scene& scene,
                                                           const RenderOptions& options,
                                                           ZBufferKind zbuffer, GlBackend gl) {
  AccelKind accel = options.accel;
  // As RayTracer::render: the SIMD kernels test triangles with Moller-Trumbore only.
  if (options.triangle_test == TriangleTest::Chapter && accel == AccelKind::Bvh)
    accel = AccelKind::Bvh2;
  auto prepared = std::make_unique<PreparedHybrid>(scene, options, accel, zbuffer, gl);
  const TraceGeometry& g = prepared->geometry();
  if (!g.error().empty()) return Error{g.error(), g.error_kind()};
  return std::unique_ptr<PreparedRenderer>(std::move(prepared));
}

}  // namespace rvr
