// The bootstrap over repetitions (see bootstrap.h).
#include "rvr/study/bootstrap.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "rvr/core/check.h"

namespace rvr::study {

uint64_t Rng::next() {
  uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

size_t Rng::below(size_t n) {
  RVR_CHECK(n > 0, "a draw below 0 has no value");
  return size_t(next() % uint64_t(n));
}

double Rng::uniform() {
  return double(next() >> 11) * 0x1.0p-53;
}

double Rng::normal() {
  double u = 1.0 - uniform();  // (0, 1]: the logarithm is finite
  double v = uniform();
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * M_PI * v);
}

namespace {

// hd_median of `values` drawn with replacement from `from`.
double resample_hd_median(const std::vector<double>& from, Rng& rng, std::vector<double>& draw) {
  draw.clear();
  for (size_t k = 0; k < from.size(); ++k) draw.push_back(from[rng.below(from.size())]);
  return hd_median(draw);
}

}  // namespace

double resample_time(const Measurement& m, Rng& rng) {
  std::vector<const Run*> runs = timed_runs(m);
  if (runs.empty()) return 0.0;
  std::vector<double> draw;
  double log_sum = 0;
  for (size_t k = 0; k < runs.size(); ++k)
    log_sum += std::log(resample_hd_median(runs[rng.below(runs.size())]->seconds, rng, draw));
  return std::exp(log_sum / double(runs.size()));
}

std::vector<double> resample_times(const std::vector<Measurement>& points, Rng& rng) {
  std::vector<double> out;
  out.reserve(points.size());
  for (const Measurement& p : points) out.push_back(resample_time(p, rng));
  return out;
}

PairedRatios paired_ratios(const Measurement& a, const Measurement& b) {
  PairedRatios p;
  for (const Run& ra : a.runs)
    for (const Run& rb : b.runs) {
      if (ra.session != rb.session) continue;
      const size_t rounds = std::min(ra.seconds.size(), rb.seconds.size());
      std::vector<double> logs;
      logs.reserve(rounds);
      for (size_t k = 0; k < rounds; ++k) logs.push_back(std::log(ra.seconds[k] / rb.seconds[k]));
      if (!logs.empty()) p.runs.push_back(std::move(logs));
      break;
    }
  return p;
}

double ratio_estimate(const PairedRatios& p) {
  if (p.runs.empty()) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0;
  for (const std::vector<double>& run : p.runs) sum += hd_median(run);
  return sum / double(p.runs.size());
}

double resample_ratio(const PairedRatios& p, Rng& rng) {
  if (p.runs.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::vector<double> draw;
  double sum = 0;
  for (size_t k = 0; k < p.runs.size(); ++k)
    sum += resample_hd_median(p.runs[rng.below(p.runs.size())], rng, draw);
  return sum / double(p.runs.size());
}

double variance(const std::vector<double>& values) {
  if (values.size() < 2) return 0.0;
  double mean = 0;
  for (double v : values) mean += v;
  mean /= double(values.size());
  double ss = 0;
  for (double v : values) ss += (v - mean) * (v - mean);
  return ss / double(values.size() - 1);
}

double quantile(std::vector<double> values, double q) {
  RVR_CHECK(q >= 0.0 && q <= 1.0, "a quantile lies in [0, 1]: ", q);
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  double pos = q * double(values.size() - 1);
  size_t lo = size_t(std::floor(pos));
  size_t hi = std::min(lo + 1, values.size() - 1);
  if (lo == hi || values[lo] == values[hi] || std::isinf(values[lo]) || std::isinf(values[hi]))
    return pos - double(lo) < 0.5 ? values[lo] : values[hi];
  return values[lo] + (pos - double(lo)) * (values[hi] - values[lo]);
}

Interval percentile_interval(const std::vector<double>& replicates) {
  return {quantile(replicates, 0.025), quantile(replicates, 0.975)};
}

}  // namespace rvr::study
