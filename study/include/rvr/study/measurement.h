// One measured point of a study: a renderer's frame of one scene size, timed several times.
#pragma once

#include <stddef.h>

#include <map>
#include <string>
#include <vector>

namespace rvr::study {

struct Measurement {
  std::string renderer;  // "softraster"
  std::string scene;     // the family: "tessphere"
  double scene_n = 0;    // the N of builtin:<scene>:N
  double n = 0;          // the swept axis' value: triangles (or occluders' depth)
  double pixels = 0;     // width x height: primary rays per frame
  int width = 0, height = 0;
  std::vector<double> seconds;  // every repetition, in the order they were timed
  std::vector<int> order;       // each repetition's position in its interleaved round
  // The reference frame timed between the rounds, at its slowest, over its quickest in the
  // family so far: how much busier the machine was than at its quietest (run_study.h).
  double reference_ratio = 0;
  bool busy = false;  // reference_ratio over kBusyRatio: left out of fits and crossovers
  // Per repetition, the seconds of each phase the renderer reports: the hybrids' "zbuffer" and
  // "trace" passes (RenderOutput::stats time.zbuffer, time.trace); empty for the others.
  std::map<std::string, std::vector<double>> phases;
};

// A point whose reference frame ran this much slower than its quickest was measured on a
// machine busy with something else.
constexpr double kBusyRatio = 1.3;

// The median of `values` (the mean of the middle two for an even count); 0 for none.
double median(std::vector<double> values);

// The sample median of a point's repetitions.
double median_seconds(const Measurement& m);

// The Harrell–Davis estimate of the median: a weighted mean of the sorted values, value i
// weighted by the chance that the median of a resample falls on it (the Beta((n+1)/2,
// (n+1)/2) mass over [(i−1)/n, i/n]). The study fits and compares this, not the sample median:
// the bootstrap of a sample median of 5 repetitions is some 35% too wide in variance (its 95%
// intervals held the truth 99% of the time in test_study), that of this estimate ~8%.
double hd_median(const std::vector<double>& values);

// hd_median's weights for n values, and the estimate from them (values in any order).
std::vector<double> hd_weights(size_t n);
double hd_median(std::vector<double> values, const std::vector<double>& weights);

// A point's time as the study uses it: hd_median of its repetitions.
double typical_seconds(const Measurement& m);

// Median absolute deviation of the repetitions, relative to their median.
double relative_mad(const Measurement& m);

}  // namespace rvr::study
