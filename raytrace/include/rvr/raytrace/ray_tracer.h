// The CPU ray tracer: "for each pixel, for each object", over a BVH or the plain loop.
#pragma once

#include <glm/glm.hpp>
#include <map>
#include <span>
#include <string>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/raytrace/primary_hit_source.h"
#include "rvr/raytrace/trace_geometry.h"

namespace rvr {

// Versions of the libraries the tracer runs on, for `rvr info`: Embree's as the headers the
// Embree plugin is built with say (nothing is loaded to tell it).
std::string embree_version();
// The widest of Embree's kernels it runs on this CPU, e.g. "AVX2" ("unknown" when the Embree
// plugin cannot be loaded; it is loaded to tell).
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
  // A frame whose primary hits come from `source` (the hybrid's z-buffer), block by block: each
  // shaded exactly as render() shades its own primary hit, with the source's texture level of
  // detail where it gives one; blocks it calls only_background are background without a ray.
  // The colour is the centre hit's only, whatever the samples per pixel: the caller adds the
  // samples with add_samples and divides by their count.
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options,
                                const TraceGeometry& geometry, const PrimaryHitSource& source);
  // Sample k (of image.samples_per_pixel) of every pixel: its ray (image_sample k: place in the
  // pixel, lens point) given to `source` for its hit, shaded with the pixel's random stream k and
  // added to sum (row-major per pixel). The sums of k = 0..spp-1 in order, divided by spp, are
  // render()'s colours bit for bit wherever the source's hits are closest()'s. Returns the
  // pass's ray counters.
  Expected<std::map<std::string, double>> add_samples(const Scene& scene,
                                                      const RenderOptions& options,
                                                      const TraceGeometry& geometry,
                                                      const PrimaryHitSource& source, int k,
                                                      std::span<glm::vec3> sum);

 private:
  Expected<RenderOutput> render_frame(const Scene& scene, const RenderOptions& options,
                                      const TraceGeometry& geometry,
                                      const PrimaryHitSource* source);

  AccelKind forced_ = AccelKind::Bvh;
  bool has_forced_ = false;
};

}  // namespace rvr
