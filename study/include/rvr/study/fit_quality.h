// How well a fitted linear model (a cost model's features, or counted work) describes the points
// it was fitted to.
#pragma once

#include <vector>

namespace rvr::study {

struct FitQuality {
  double r2 = 0;                // 1 − Σ w·r² / Σ w·(t − t̄_w)², w = 1/t²
  double max_rel_residual = 0;  // max |t − model| / t
  // Each point predicted by the model fitted to all the others: |t_i − model without i| / t_i,
  // its median and mean over the points (inf when a refit fails).
  double loo_median_rel_error = 0;
  double loo_mean_rel_error = 0;
};

// The leave-one-out errors alone (what choosing among models needs): `rows` holds each point's
// features, `times` its measured time; every refit is the non-negative weighted fit of fit.h.
FitQuality leave_one_out(const std::vector<std::vector<double>>& rows,
                         const std::vector<double>& times, const std::vector<bool>& use);

FitQuality fit_quality(const std::vector<std::vector<double>>& rows,
                       const std::vector<double>& times, const std::vector<double>& coefficients,
                       const std::vector<bool>& use);

}  // namespace rvr::study
