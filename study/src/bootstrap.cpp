// The bootstrap over repetitions (see bootstrap.h).
#include "rvr/study/bootstrap.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rvr/shared/check.h"

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

std::vector<double> resample_medians(const std::vector<Measurement>& points, Rng& rng) {
  std::vector<double> medians;
  medians.reserve(points.size());
  std::vector<double> draw, weights;
  for (const Measurement& p : points) {
    draw.clear();
    for (size_t k = 0; k < p.seconds.size(); ++k)
      draw.push_back(p.seconds[rng.below(p.seconds.size())]);
    if (weights.size() != draw.size()) weights = hd_weights(draw.size());
    medians.push_back(hd_median(draw, weights));
  }
  return medians;
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
