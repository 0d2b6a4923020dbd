// Which scene sizes a study measures: the families it sweeps, their log-spaced grids, the
// points added near a crossover, the share of the planned points a shard measures, and the
// cost of a point predicted from those measured.
#pragma once

#include <stddef.h>

#include <map>
#include <string>
#include <vector>

#include "rvr/core/expected.h"

namespace rvr::study {

struct Family {
  std::string name;          // "tessphere", or a file's name: "bunny.obj"
  std::string axis;          // "triangles", or "depth" for occluders (quads one behind another)
  size_t low = 0, high = 0;  // the N of builtin:name:N swept, or the number of copies of a file
  int points = 0;            // log-spaced between them
  std::string source;        // a scene or model file, grown by grid_of_copies; "" for built-ins
  // The largest N a session may hold in the machine's memory (memory_estimate.h); 0: no limit.
  // Planned N above it are dropped from the sweep.
  size_t max_n = 0;
};

// Points per decade of N of the built-in triangle families: the trend through a point and its
// neighbours (trend.h) spans about a decade, and a crossover needs two significant points on
// each side of it.
constexpr int kPointsPerDecade = 4;

// How far the built-in triangle families are swept: past the z-buffer/tracer crossovers (about
// 2-3×10^6 triangles on tessphere, 5-10×10^6 on soup at 1024×768 on a 2-core machine) by
// at least two points of the grid on each side.
// On the grid 10^(k/4): 10^7.25 and 10^7.5.
constexpr size_t kTessphereHigh = 17'782'794;
constexpr size_t kSoupHigh = 31'622'777;

// The pixel sweep is taken at N up to this: above it every session builds the tracers' BVH
// again for each of the narrower widths (seconds to minutes per point), and the per-pixel terms
// are told apart from the points at smaller N already.
constexpr size_t kPixelSweepMaxN = 1'000'000;

// The most triangles a file's grid of copies is grown to.
constexpr double kFileFamilyTriangles = 2e6;

// "builtin:tessphere" (or "tessphere"; soup and effects alike: 10^2 … kTessphereHigh or
// kSoupHigh, kPointsPerDecade a decade), "builtin:occluders" (depth 1 … 256), or the path of a
// scene or model file: 1 … K copies of it with K such that they hold about
// kFileFamilyTriangles (4 … 1024). A BadInput error naming the families for any other
// built-in, and the loader's error for a file that does not load.
Expected<Family> find_family(const std::string& name);

// `count` values from low to high, evenly spaced in log, rounded, without repeats.
std::vector<size_t> log_spaced(size_t low, size_t high, int count);

// The narrower widths of the pixel sweep under `width`: width·2^(−k/2) for k = 1 … 4 (so the
// pixel count falls by 16× in steps of 2×), rounded to multiples of 4, at least 16, in
// increasing order, without repeats.
std::vector<int> pixel_sweep_widths(int width);

// The N at which the pixel sweep is taken, of those measured at the full width (in increasing
// order) up to kPixelSweepMaxN: the smallest, the one nearest their geometric middle, and the
// largest.
std::vector<size_t> pixel_sweep_ns(const std::vector<size_t>& measured);

// A point a sweep plans: builtin:<family>:<n> (or n copies of the family's file) at `width`.
struct PlannedPoint {
  size_t n = 0;
  int width = 0;
};

// The N a sweep of `family` plans at the full width: log-spaced from low to high, less those
// above family.max_n.
std::vector<size_t> sweep_ns(const Family& family);

// The points a sweep of `family` at `width` plans, in the order it takes them: sweep_ns at the
// full width, then the pixel sweep's narrower widths at pixel_sweep_ns of those N (a
// sweep the budget stops takes them at pixel_sweep_ns of the N it measured). Points near
// crossovers depend on the measurements and are not planned. --shard divides these points,
// numbered through the families in the order the study takes them.
std::vector<PlannedPoint> planned_points(const Family& family, int width);

// The rounded geometric mean of two neighbours: the point that halves a bracket in log; 0 when
// they are too close to hold one.
size_t log_midpoint(size_t low, size_t high);

// One of `count` studies that together measure a sweep's planned points (--shard I/N).
struct Shard {
  size_t index = 0;  // 0 .. count-1
  size_t count = 1;
};

// "I/N" with 0 <= I < N; a BadInput error "--shard: ..." for anything else.
Expected<Shard> parse_shard(const std::string& text);

// Whether the point at `plan_index` in the sweep's planned points is the shard's to measure:
// every point whose index is ≡ shard.index mod shard.count.
bool in_shard(size_t plan_index, const Shard& shard);

// Predicts the wall time of measuring a point at N from the points measured so far: their
// cost grown along the log-log slope of the last two (clamped to 0 .. 1.5; 1 from one point),
// or the cost of the nearest point above N.
class CostPredictor {
 public:
  void add(size_t n, double seconds) { measured_[n] = seconds; }
  bool empty() const { return measured_.empty(); }
  double predict(size_t n) const;

 private:
  std::map<size_t, double> measured_;
};

}  // namespace rvr::study
