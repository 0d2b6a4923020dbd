// Weighted linear least squares for a handful of coefficients, unconstrained or with every
// coefficient non-negative (the study's unit costs: a renderer never saves time by doing work).
#pragma once

#include <vector>

#include "rvr/core/expected.h"

namespace rvr::study {

// The β minimizing Σ_i w_i (y_i − x_i·β)², by Householder QR of the weighted rows with every
// column scaled to unit size first (the columns span 1 to 10^7). Columns whose `use` flag is
// false are left out and get β = 0. An error when there are fewer rows than columns used or
// the columns used are (nearly) dependent.
Expected<std::vector<double>> weighted_least_squares(const std::vector<std::vector<double>>& x,
                                                     const std::vector<double>& y,
                                                     const std::vector<double>& w,
                                                     const std::vector<bool>& use);

// The same minimum over β ≥ 0: Lawson and Hanson's active-set algorithm (Solving Least Squares
// Problems, 1974, ch. 23) on the weighted, column-scaled system, each passive-set subproblem
// solved by Householder QR. A coefficient the constraint holds at its bound is exactly 0. The
// same errors as weighted_least_squares (dependent columns are refused even when the
// constrained minimum happens to be unique: the study reports no coefficient it cannot
// tell apart from another).
Expected<std::vector<double>> nonnegative_least_squares(const std::vector<std::vector<double>>& x,
                                                        const std::vector<double>& y,
                                                        const std::vector<double>& w,
                                                        const std::vector<bool>& use);

}  // namespace rvr::study
