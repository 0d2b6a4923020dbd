// The hierarchical bootstrap (Kalibera & Jones): a point's runs drawn with replacement, then
// each drawn run's rounds drawn with replacement, so that a replicate varies as much as a new
// set of processes would, not only as much as new frames in the same ones.
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

// A point's time in one replicate: its timed runs drawn with replacement, each drawn run's
// rounds drawn with replacement, and typical_seconds of what was drawn (the geometric mean of
// the runs' Harrell–Davis medians).
double resample_time(const Measurement& m, Rng& rng);

// resample_time of every point, in order.
std::vector<double> resample_times(const std::vector<Measurement>& points, Rng& rng);

// a's and b's frames at one point paired round by round within each session both measured in:
// per session, the rounds' log(t_a / t_b). Interleaved in one round, the two frames saw the
// same machine: a load that slows both cancels in the ratio.
struct PairedRatios {
  std::vector<std::vector<double>> runs;
};
PairedRatios paired_ratios(const Measurement& a, const Measurement& b);

// The point's log ratio: the mean over runs of each run's Harrell–Davis median.
double ratio_estimate(const PairedRatios& p);

// ratio_estimate of one hierarchical resample (runs, then rounds within each).
double resample_ratio(const PairedRatios& p, Rng& rng);

// The q-quantile (0..1) of `values`, linear between order statistics; infinities are ordered
// like numbers. NaN for none.
double quantile(std::vector<double> values, double q);

struct Interval {
  double low = 0, high = 0;
};

// The central 95% of the replicates' values (2.5% and 97.5% quantiles).
Interval percentile_interval(const std::vector<double>& replicates);

// The sample variance of `values` (0 for fewer than two).
double variance(const std::vector<double>& values);

// How many replicates the study draws, and the seed of the first.
struct BootstrapOptions {
  int replicates = 1000;
  uint64_t seed = 1;
};

}  // namespace rvr::study
