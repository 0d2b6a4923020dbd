// Primary hits found by the caller instead of the tracer's own centre rays: the tracer asks a
// PrimaryHitSource for them one block of pixels at a time (at most kPacketSide on a side, from the
// tiles' threads in parallel), then shades them exactly as it shades its own. The hybrid's
// z-buffer answers this way (hybrid/src/zbuffer_hits.h); the tracer knows nothing of how.
#pragma once

#include <cstdint>

#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

// The centre rays of pixels [x0, x1) x [y0, y1), ray k the pixel (x0 + k % w, y0 + k / w) with
// w = x1 - x0, as RayTracer::render traces them; the source fills the rest.
struct CentreBlock {
  int x0, y0, x1, y1;
  const RayPacket& packet;
  // The source writes every ray's hits[k] and work[k]: they arrive unset (PacketSlots).
  HitRecord* hits;          // each ray's closest hit (primitive kNoPrimitive: none, background)
  TraversalCounters* work;  // each ray's traversal work: its pixel's cost AOV
  // Where given[k], the texture level of detail ray k's hit samples at instead of its own
  // footprint's.
  float* given_lod;
  bool* given;
  uint64_t rays = 0;               // primary rays the block counts (rays.primary)
  TraversalCounters unattributed;  // traversal work done for the block but for no pixel
};

// One sample's rays (RayTracer::add_samples) for pixels [x0, x1) x [y0, y1), row by row.
struct SampleBlock {
  int x0, y0, x1, y1;
  const Ray* rays;
  HitRecord* hits;  // as CentreBlock's
  float* given_lod;
  bool* given;
  TraversalCounters work;  // the block's traversal work
};

class PrimaryHitSource {
 public:
  virtual ~PrimaryHitSource() = default;
  // Whether every pixel of [x0, x1) x [y0, y1) is background, known without a ray: the tracer
  // then writes them so without generating the block's rays.
  virtual bool only_background(int x0, int y0, int x1, int y1) const = 0;
  // Every ray's hit of a block not only_background.
  virtual void centre_hits(CentreBlock& block) const = 0;
  // Every sample ray's hit.
  virtual void sample_hits(SampleBlock& block) const = 0;
};

}  // namespace rvr
