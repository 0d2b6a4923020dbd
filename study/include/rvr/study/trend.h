// The trend a noisy curve follows: at each point, a straight line through its k nearest
// neighbours (itself included) along x, evaluated there. Linear in the values (trend = H·y),
// so H says how much each point weighs in each trend value, and the scatter of the points
// about their trend measures the noise between points that no repetition of one point shows.
#pragma once

#include <stddef.h>

#include <vector>

namespace rvr::study {

// The neighbours each trend value is fitted to.
constexpr size_t kTrendNeighbours = 5;

class Trend {
 public:
  // x in increasing order, at least two distinct values.
  explicit Trend(const std::vector<double>& x, size_t neighbours = kTrendNeighbours);

  // The trend of `y` (one value per x) at every x.
  std::vector<double> apply(const std::vector<double>& y) const;

  // H[j][i]: the weight of y_i in the trend at x_j.
  const std::vector<std::vector<double>>& weights() const { return h_; }

  // The residual degrees of freedom, tr((I − H)ᵀ(I − H)): Σ (y − H·y)² over it estimates the
  // variance of independent noise of equal variance on every y.
  double residual_dof() const { return residual_dof_; }

  // That estimate from the values themselves; 0 when residual_dof is 0.
  double residual_variance(const std::vector<double>& y) const;

 private:
  std::vector<std::vector<double>> h_;
  double residual_dof_ = 0;
};

// Where a piecewise-linear curve through (x_i, y_i) crosses zero between x[from] and x[to]
// (from < to, y of opposite signs there), by linear interpolation: the first crossing from
// `from` and the last before `to`, averaged when they differ.
double zero_crossing(const std::vector<double>& x, const std::vector<double>& y, size_t from,
                     size_t to);

}  // namespace rvr::study
