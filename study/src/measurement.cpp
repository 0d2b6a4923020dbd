// Medians and spreads of repeated timings.
#include "rvr/study/measurement.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "rvr/core/check.h"

namespace rvr::study {

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  double upper = values[mid];
  if (values.size() % 2) return upper;
  double lower = *std::max_element(values.begin(), values.begin() + mid);
  return 0.5 * (lower + upper);
}

namespace {

// ∫ x^(a−1) (1−x)^(a−1) dx over [lo, hi], by Simpson's rule (a ≥ 1: the integrand is smooth).
double beta_mass(double a, double lo, double hi) {
  const int steps = 64;
  const double h = (hi - lo) / steps;
  auto f = [a](double x) { return std::pow(x, a - 1) * std::pow(1 - x, a - 1); };
  double sum = f(lo) + f(hi);
  for (int i = 1; i < steps; ++i) sum += f(lo + i * h) * (i % 2 ? 4 : 2);
  return sum * h / 3;
}

}  // namespace

std::vector<double> hd_weights(size_t count) {
  const double n = double(count), a = (n + 1) / 2;
  std::vector<double> w;
  double sum = 0;
  for (size_t i = 0; i < count; ++i) {
    w.push_back(beta_mass(a, double(i) / n, double(i + 1) / n));
    sum += w.back();
  }
  RVR_CHECK(count == 0 || sum > 0.0, "the Beta masses of [0, 1] add up to 1, not ", sum);
  for (double& x : w) x /= sum;
  return w;
}

double hd_median(std::vector<double> values, const std::vector<double>& weights) {
  if (values.empty()) return 0.0;
  RVR_CHECK(weights.size() == values.size(), "Harrell-Davis weights for ", weights.size(),
            " values applied to ", values.size());
  std::sort(values.begin(), values.end());
  double total = 0;
  for (size_t i = 0; i < values.size(); ++i) total += weights[i] * values[i];
  return total;
}

double hd_median(const std::vector<double>& values) {
  // The weights depend only on the count: computed once per count and thread (the bootstrap
  // asks for the same few counts millions of times).
  thread_local std::vector<std::vector<double>> cache;
  const size_t n = values.size();
  if (n >= 256) return hd_median(values, hd_weights(n));
  if (cache.size() <= n) cache.resize(n + 1);
  if (cache[n].size() != n) cache[n] = hd_weights(n);
  return hd_median(values, cache[n]);
}

bool Measurement::busy() const {
  if (runs.empty()) return false;
  for (const Run& r : runs)
    if (!r.busy) return false;
  return true;
}

size_t Measurement::frames() const {
  size_t count = 0;
  for (const Run& r : runs) count += r.seconds.size();
  return count;
}

std::vector<const Run*> timed_runs(const Measurement& m) {
  std::vector<const Run*> quiet, all;
  for (const Run& r : m.runs) {
    if (r.seconds.empty()) continue;
    all.push_back(&r);
    if (!r.busy) quiet.push_back(&r);
  }
  return quiet.empty() ? all : quiet;
}

double typical_seconds(const Measurement& m) {
  std::vector<const Run*> runs = timed_runs(m);
  if (runs.empty()) return 0.0;
  double log_sum = 0;
  for (const Run* r : runs) log_sum += std::log(hd_median(r->seconds));
  return std::exp(log_sum / double(runs.size()));
}

std::vector<double> all_seconds(const Measurement& m) {
  std::vector<double> out;
  for (const Run* r : timed_runs(m)) out.insert(out.end(), r->seconds.begin(), r->seconds.end());
  return out;
}

double median_seconds(const Measurement& m) {
  return median(all_seconds(m));
}

double relative_mad(const Measurement& m) {
  std::vector<double> seconds = all_seconds(m);
  double med = median(seconds);
  if (med <= 0) return 0.0;
  std::vector<double> deviations;
  deviations.reserve(seconds.size());
  for (double s : seconds) deviations.push_back(std::fabs(s - med));
  return median(deviations) / med;
}

}  // namespace rvr::study
