// How well a fitted cost model describes the points it was fitted to.
#pragma once

#include <vector>

#include "rvr/study/cost_model.h"
#include "rvr/study/measurement.h"

namespace rvr::study {

struct FitQuality {
  double r2 = 0;                // 1 − Σ w·r² / Σ w·(t − t̄_w)², w = 1/t²
  double max_rel_residual = 0;  // max |t − model| / t
  double loo_rel_error = 0;  // RMS of |t_i − model without i (at i)| / t_i; inf if a refit fails
};

FitQuality fit_quality(ModelForm form, const std::vector<Measurement>& points,
                       const std::vector<double>& medians, const std::vector<double>& coefficients,
                       const std::vector<bool>& use);

}  // namespace rvr::study
