// The bootstrap over repetitions: every point of a sweep is kept, and each point's median is
// recomputed from its own repetitions drawn with replacement. What varies between replicates is
// then the timing noise of each point, never which points were swept.
#pragma once

#include <stddef.h>

#include <cstdint>
#include <vector>

#include "rvr/study/measurement.h"

namespace rvr::study {

// splitmix64: a fixed generator, so a seed gives the same intervals on every platform.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next();
  // Uniform in 0 .. n-1 (n > 0).
  size_t below(size_t n);
  // Uniform in [0, 1).
  double uniform();
  // Standard normal (Box–Muller).
  double normal();

 private:
  uint64_t state_;
};

// One replicate: for each point, in order, the hd_median of as many repetitions as it has,
// drawn with replacement from its own.
std::vector<double> resample_medians(const std::vector<Measurement>& points, Rng& rng);

// The q-quantile (0..1) of `values`, linear between order statistics; infinities are ordered
// like numbers. NaN for none.
double quantile(std::vector<double> values, double q);

struct Interval {
  double low = 0, high = 0;
};

// The central 95% of the replicates' values (2.5% and 97.5% quantiles).
Interval percentile_interval(const std::vector<double>& replicates);

// How many replicates the study draws, and the seed of the first.
struct BootstrapOptions {
  int replicates = 1000;
  uint64_t seed = 1;
};

}  // namespace rvr::study
