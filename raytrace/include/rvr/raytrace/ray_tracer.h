// The CPU ray tracer: "for each pixel, for each object", over a BVH or the plain loop.
#pragma once

#include <string>

#include "rvr/raytrace/primary_visibility.h"
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
  // A frame whose primary hits come from outside (the hybrid: a z-buffer's ids): each pixel's
  // centre ray is intersected with the one object or triangle `visible` names there, then
  // shaded exactly as render() shades its primary hit. Pixels where that misses or nothing was
  // drawn are traced as render() traces them, and the CSG objects (no z-buffer draws them) are
  // intersected for every pixel, the nearer hit kept: the same image as render() wherever the
  // ids agree with its own. Stats add hybrid.rebuilt, hybrid.fallback_traced (of which
  // hybrid.fallback_missed: the named primitive was missed) and hybrid.csg_pixels.
  Expected<RenderOutput> render_visible(const Scene& scene, const RenderOptions& options,
                                        const TraceGeometry& geometry,
                                        const PrimaryVisibility& visible);

 private:
  Expected<RenderOutput> render_frame(const Scene& scene, const RenderOptions& options,
                                      const TraceGeometry& geometry,
                                      const PrimaryVisibility* visible);

  AccelKind forced_ = AccelKind::Bvh;
  bool has_forced_ = false;
};

}  // namespace rvr
