// The CPU ray tracer: "for each pixel, for each object", over a BVH or the plain loop.
#pragma once

#include <glm/glm.hpp>
#include <map>
#include <span>
#include <string>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/raytrace/primary_visibility.h"
#include "rvr/raytrace/trace_geometry.h"

namespace rvr {

// Versions of the libraries the tracer runs on, for `rvr info`: Embree's as the headers the
// Embree plugin is built with say (nothing is loaded to tell it).
std::string embree_version();
// The widest of Embree's kernels it runs on this CPU, e.g. "AVX2" ("unknown" when the Embree
// plugin cannot be loaded; it is loaded to tell).
std::string embree_kernel_isa();
std::string tbb_version();

// Where render_visible takes a pixel's samples from when the scene asks for several: traced by
// the tracer itself, or from the caller's accumulation-buffer passes (add_visible_sample).
enum class VisibleSamples { Traced, FromPasses };

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
  // With VisibleSamples::FromPasses and several samples per pixel, the colour is the centre
  // ray's only; the caller adds the samples with add_visible_sample and divides by their count.
  Expected<RenderOutput> render_visible(const Scene& scene, const RenderOptions& options,
                                        const TraceGeometry& geometry,
                                        const PrimaryVisibility& visible,
                                        VisibleSamples samples = VisibleSamples::Traced);
  // One pass of the hybrid's accumulation buffer: sample k (of image.samples_per_pixel) of every
  // pixel, its ray (image_sample k: place in the pixel, lens point) intersected with what
  // `visible` names there (a z-buffer drawn with RenderOptions::image_sample = that sample),
  // else traced, CSG as render_visible. Each colour is added to sum (row-major per pixel): the
  // sums of passes k = 0..spp-1 in order, divided by spp, are render()'s colours bit for bit
  // wherever the ids agree with its own hits. Returns the pass's ray and hybrid counters.
  Expected<std::map<std::string, double>> add_visible_sample(const Scene& scene,
                                                             const RenderOptions& options,
                                                             const TraceGeometry& geometry,
                                                             const PrimaryVisibility& visible,
                                                             int k, std::span<glm::vec3> sum);

 private:
  Expected<RenderOutput> render_frame(const Scene& scene, const RenderOptions& options,
                                      const TraceGeometry& geometry,
                                      const PrimaryVisibility* visible, bool centre_only);

  AccelKind forced_ = AccelKind::Bvh;
  bool has_forced_ = false;
};

}  // namespace rvr
