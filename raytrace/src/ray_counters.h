// The tracer's work counters, each declared once in the lists below (its field, the stat it is
// reported as, the frames that report it): RayCounters holds them, adds one thread's to the
// total and writes them into RenderOutput::stats from those lines alone, as pbrt-v4 declares a
// statistic once with STAT_COUNTER. docs/cli.md describes each stat.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "rvr/raytrace/bvh.h"

namespace rvr {

// Which frames report a counter: every frame; frames over rvr's own BVHs (Embree does not count
// its traversal steps).
enum class ReportedIn { EveryFrame, OwnTraversal };

// X(field, stat, reported in) for the counts RayCounters holds itself.
#define RVR_RAY_COUNTS(X)                      \
  X(primary, "rays.primary", EveryFrame)       \
  X(shadow, "rays.shadow", EveryFrame)         \
  X(reflection, "rays.reflection", EveryFrame) \
  X(refraction, "rays.refraction", EveryFrame) \
  X(primary_culled, "rays.primary_culled", EveryFrame)

// X(field, stat, reported in) for the counts of TraversalCounters (bvh.h), which the traversal
// kernels fill.
#define RVR_TRAVERSAL_COUNTS(X)                       \
  X(nodes_visited, "bvh.nodes_visited", OwnTraversal) \
  X(primitive_tests, "primitive_tests", OwnTraversal)

struct RayCounters {
#define RVR_DECLARE_COUNT(field, stat, reported_in) uint64_t field = 0;
  RVR_RAY_COUNTS(RVR_DECLARE_COUNT)
#undef RVR_DECLARE_COUNT
  TraversalCounters traversal;
  // Thread time spent on tiles, and of it after the primary hits were known (surfaces, AOVs,
  // shading), in cycle_ticks: how a frame's time divides between visibility and shading.
  uint64_t busy_ticks = 0, shade_ticks = 0;

  uint64_t rays() const {
    return primary + shadow + reflection + refraction;
  }

  void add(const RayCounters& o) {
#define RVR_ADD_COUNT(field, stat, reported_in) field += o.field;
    RVR_RAY_COUNTS(RVR_ADD_COUNT)
#undef RVR_ADD_COUNT
#define RVR_ADD_TRAVERSAL_COUNT(field, stat, reported_in) traversal.field += o.traversal.field;
    RVR_TRAVERSAL_COUNTS(RVR_ADD_TRAVERSAL_COUNT)
#undef RVR_ADD_TRAVERSAL_COUNT
    busy_ticks += o.busy_ticks;
    shade_ticks += o.shade_ticks;
  }

  // Writes every counter the frame reports into `stats` under its stat's name: `own_traversal`
  // for a frame over rvr's own BVH.
  void report(std::map<std::string, double>& stats, bool own_traversal) const {
    const auto reported = [&](ReportedIn in) {
      return in == ReportedIn::EveryFrame || (in == ReportedIn::OwnTraversal && own_traversal);
    };
#define RVR_REPORT_COUNT(field, stat, reported_in) \
  if (reported(ReportedIn::reported_in)) stats[stat] = double(field);
    RVR_RAY_COUNTS(RVR_REPORT_COUNT)
#undef RVR_REPORT_COUNT
#define RVR_REPORT_TRAVERSAL_COUNT(field, stat, reported_in) \
  if (reported(ReportedIn::reported_in)) stats[stat] = double(traversal.field);
    RVR_TRAVERSAL_COUNTS(RVR_REPORT_TRAVERSAL_COUNT)
#undef RVR_REPORT_TRAVERSAL_COUNT
  }
};

}  // namespace rvr
