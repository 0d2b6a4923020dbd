// Local straight-line trends (see trend.h).
#include "rvr/study/trend.h"

#include <algorithm>
#include <cmath>

#include "rvr/core/check.h"

namespace rvr::study {

Trend::Trend(const std::vector<double>& x, size_t neighbours) {
  const size_t n = x.size();
  RVR_CHECK(n >= 2 && x.front() < x.back(), "a trend needs two distinct x, got ", n, " values");
  const size_t k = std::min(std::max<size_t>(neighbours, 2), n);
  h_.assign(n, std::vector<double>(n, 0.0));
  std::vector<size_t> order(n);
  for (size_t j = 0; j < n; ++j) {
    for (size_t i = 0; i < n; ++i) order[i] = i;
    // The k nearest; ties broken towards lower x so the window is the same for equal spacing.
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return std::fabs(x[a] - x[j]) < std::fabs(x[b] - x[j]);
    });
    double sx = 0, sxx = 0;
    for (size_t m = 0; m < k; ++m) sx += x[order[m]], sxx += x[order[m]] * x[order[m]];
    const double mean = sx / double(k), sdev = sxx - double(k) * mean * mean;
    // Least squares over the window: trend(x_j) = ȳ + slope·(x_j − x̄), each linear in y_i.
    for (size_t m = 0; m < k; ++m) {
      const size_t i = order[m];
      double w = 1.0 / double(k);
      if (sdev > 1e-12 * std::max(1.0, sxx)) w += (x[j] - mean) * (x[i] - mean) / sdev;
      h_[j][i] = w;
    }
  }
  // tr((I − H)ᵀ(I − H)) = Σ_j Σ_i (δ_ij − H_ji)²
  for (size_t j = 0; j < n; ++j)
    for (size_t i = 0; i < n; ++i) {
      const double r = (i == j ? 1.0 : 0.0) - h_[j][i];
      residual_dof_ += r * r;
    }
}

std::vector<double> Trend::apply(const std::vector<double>& y) const {
  RVR_CHECK(y.size() == h_.size(), "one value per x: ", y.size(), " for ", h_.size());
  std::vector<double> out(y.size(), 0.0);
  for (size_t j = 0; j < h_.size(); ++j)
    for (size_t i = 0; i < y.size(); ++i) out[j] += h_[j][i] * y[i];
  return out;
}

double Trend::residual_variance(const std::vector<double>& y) const {
  if (residual_dof_ < 1e-9) return 0.0;
  std::vector<double> t = apply(y);
  double ss = 0;
  for (size_t i = 0; i < y.size(); ++i) ss += (y[i] - t[i]) * (y[i] - t[i]);
  return ss / residual_dof_;
}

double zero_crossing(const std::vector<double>& x, const std::vector<double>& y, size_t from,
                     size_t to) {
  RVR_CHECK(from < to && to < x.size() && x.size() == y.size(),
            "a bracket inside the curve: ", from, "..", to, " of ", x.size());
  auto crossing = [&](size_t i) {  // between i and i + 1, y changing sign there
    if (y[i] == y[i + 1]) return x[i];
    const double f = y[i] / (y[i] - y[i + 1]);
    return x[i] + f * (x[i + 1] - x[i]);
  };
  auto changes = [&](size_t i) { return (y[i] < 0) != (y[i + 1] < 0) || y[i] == 0; };
  size_t first = from, last = to - 1;
  while (first < to - 1 && !changes(first)) ++first;
  while (last > from && !changes(last)) --last;
  return 0.5 * (crossing(first) + crossing(last));
}

}  // namespace rvr::study
