// The CPU ray tracer: "for each pixel, for each object", over a BVH or the plain loop.
#pragma once

#include <string>

#include "rvr/raytrace/trace_geometry.h"
#include "rvr/shared/renderer.h"

namespace rvr {

// Versions of the libraries the tracer runs on, for `rvr info`.
std::string embree_version();
// The widest of Embree's kernels it runs on this CPU, e.g. "AVX2".
std::string embree_kernel_isa();
std::string tbb_version();

class RayTracer : public Renderer {
 public:
  RayTracer() = default;
  // The same tracer with its queries answered by one accelerator whatever the options say:
  // AccelKind::Embree is the "embree" renderer, the yardstick for our BVH.
  explicit RayTracer(AccelKind forced) : forced_(forced), has_forced_(true) {}

  std::string name() const override {
    return has_forced_ && forced_ == AccelKind::Embree ? "embree" : "raytrace";
  }
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options) override;
  // A frame over geometry built beforehand from the same scene (benchmarks build once and time
  // frames only); its accelerator and sphere mode win over the options'.
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options,
                                const TraceGeometry& geometry);

 private:
  AccelKind forced_ = AccelKind::Bvh;
  bool has_forced_ = false;
};

}  // namespace rvr
