// Weighted linear least squares for a handful of coefficients.
#pragma once

#include <vector>

#include "rvr/shared/expected.h"

namespace rvr::study {

// The β minimizing Σ_i w_i (y_i − x_i·β)², by Householder QR of the weighted rows with every
// column scaled to unit size first (the columns span 1 to 10^7). Columns whose `use` flag is
// false are left out and get β = 0. An error when there are fewer rows than columns used or
// the columns used are (nearly) dependent.
Expected<std::vector<double>> weighted_least_squares(const std::vector<std::vector<double>>& x,
                                                     const std::vector<double>& y,
                                                     const std::vector<double>& w,
                                                     const std::vector<bool>& use);

}  // namespace rvr::study
