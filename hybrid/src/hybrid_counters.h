// The hybrid's own counters: how each pixel's primary hit was found. Reported as hybrid.*
// (docs/cli.md) beside the tracer's ray counters.
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace rvr {

// X(field, stat): pixels whose hit was rebuilt from the z-buffer's ids, traced instead (missed
// or empty), and won by a CSG object; samples whose rebuilt hit a shape the z-buffer draws
// approximately won (sample passes); of those traced, the ones whose named primitive the ray
// missed (silhouettes, edges); empty pixels left as background without a ray.
#define RVR_HYBRID_COUNTS(X)                           \
  X(rebuilt, "hybrid.rebuilt")                         \
  X(fallback_traced, "hybrid.fallback_traced")         \
  X(fallback_missed, "hybrid.fallback_missed")         \
  X(csg_pixels, "hybrid.csg_pixels")                   \
  X(approximated_pixels, "hybrid.approximated_pixels") \
  X(background, "hybrid.background")

struct HybridCounters {
#define RVR_DECLARE_COUNT(field, stat) uint64_t field = 0;
  RVR_HYBRID_COUNTS(RVR_DECLARE_COUNT)
#undef RVR_DECLARE_COUNT

  void add(const HybridCounters& o) {
#define RVR_ADD_COUNT(field, stat) field += o.field;
    RVR_HYBRID_COUNTS(RVR_ADD_COUNT)
#undef RVR_ADD_COUNT
  }

  // Adds every counter to `stats` under its stat's name.
  void add_to(std::map<std::string, double>& stats) const {
#define RVR_REPORT_COUNT(field, stat) stats[stat] += double(field);
    RVR_HYBRID_COUNTS(RVR_REPORT_COUNT)
#undef RVR_REPORT_COUNT
  }
};

}  // namespace rvr
