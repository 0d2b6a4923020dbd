// Medians and spreads of repeated timings.
#include "rvr/study/measurement.h"

#include <algorithm>
#include <cmath>

#include "rvr/shared/check.h"

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

double median_seconds(const Measurement& m) {
  return median(m.seconds);
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
  return hd_median(values, hd_weights(values.size()));
}

double typical_seconds(const Measurement& m) {
  return hd_median(m.seconds);
}

double relative_mad(const Measurement& m) {
  double med = median(m.seconds);
  if (med <= 0) return 0.0;
  std::vector<double> deviations;
  for (double s : m.seconds) deviations.push_back(std::fabs(s - med));
  return median(deviations) / med;
}

}  // namespace rvr::study
