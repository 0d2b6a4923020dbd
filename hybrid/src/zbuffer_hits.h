// The hybrid's primary hits: each pixel's hit rebuilt from the one primitive the z-buffer's
// visibility buffer names there, traced where the z-buffer cannot answer (empty pixels next to
// what it drew, named primitives the exact ray misses), and background without a ray everywhere
// else. The shapes a z-buffer draws approximately or not at all (analytic spheres and discs,
// CSG solids) are intersected besides where they may appear, the nearer hit kept.
#pragma once

#include <stddef.h>
#include <tbb/combinable.h>

#include <cstdint>
#include <span>

#include "hybrid_counters.h"
#include "primary_visibility.h"
#include "rvr/core/ray.h"
#include "rvr/core/scene.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/primary_hit_source.h"
#include "rvr/raytrace/trace_geometry.h"

namespace rvr {

class ZBufferHits : public PrimaryHitSource {
 public:
  // `approximated`: 1 at the pixels where a shape the z-buffer draws approximately or not at all
  // may appear (approximated_pixels), row-major; empty: none. There the z-buffer may show
  // nothing, or a surface behind the shape, where the tracer sees the shape: those shapes are
  // intersected besides the z-buffer's hit there. A sample pass (sample_hits) needs none: its
  // rays are checked against those shapes wherever the z-buffer's hit is rebuilt.
  ZBufferHits(const Scene& scene, const TraceGeometry& geometry, const PrimaryVisibility& visible,
              std::span<const uint8_t> approximated = {});

  bool only_background(int x0, int y0, int x1, int y1) const override;
  void centre_hits(CentreBlock& block) const override;
  void sample_hits(SampleBlock& block) const override;

  // Every thread's counters added up.
  HybridCounters counters() const;

 private:
  bool next_to_drawn(int x, int y) const;
  void drawn_nearby(const CentreBlock& block, uint32_t* rows) const;
  void fetch_next_block(const CentreBlock& block) const;
  // Pixel i lies where a shape the z-buffer draws approximately may appear.
  bool approximated_at(size_t i) const { return !approximated_.empty() && approximated_[i]; }
  // Whether the hit a shape the z-buffer draws approximately or not at all (spheres, discs, CSG
  // solids) gives `ray` is nearer than `hit` (ties by primitive index, as closest() breaks them);
  // if so `hit` becomes it.
  bool approximated_wins(const Ray& ray, HitRecord& hit, TraversalCounters& work) const;
  // Whether `hit` is on a CSG object.
  bool csg_hit(const HitRecord& hit) const;

  const Scene& scene_;
  const TraceGeometry& geometry_;
  PrimaryVisibility visible_;
  std::span<const uint8_t> approximated_;
  mutable tbb::combinable<HybridCounters> counters_;
};

}  // namespace rvr
