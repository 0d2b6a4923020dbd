// A cost model fitted to a renderer's sweep: weighted least squares on relative error, 95%
// intervals from the bootstrap over repetitions, and whether the model fits at all.
#pragma once

#include <stddef.h>

#include <string>
#include <vector>

#include "rvr/shared/expected.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/measurement.h"

namespace rvr::study {

struct Coefficient {
  std::string name;
  double value = 0;
  Interval ci95;
  // False for b when every point had the same pixel count: a then holds a + b·P.
  bool identifiable = true;
};

// What a model must achieve before the study draws conclusions from it.
struct FitThresholds {
  double min_r2 = 0.9;
  double max_rel_residual = 0.25;
  double max_loo_rel_error = 0.20;
  // An extension is taken only when it lowers the mean leave-one-out error by this fraction.
  double min_extension_gain = 0.20;
};

struct ModelFit {
  CostModel model;
  std::string formula;    // the model fitted, with any extension the data demanded
  std::string selection;  // why this model and not the textbook form or another extension
  std::vector<Coefficient> coefficients;
  double r2 = 0;                // weighted (1/t²) coefficient of determination
  double max_rel_residual = 0;  // largest |t − model| / t over the points
  double loo_rel_error = 0;     // median over the points of their error when left out
  size_t points = 0;
  bool fits = false;
  std::string verdict;      // "fits", or why the model does not
  double fixed_pixels = 0;  // > 0: every point had this P, so b is folded into a
  // The coefficients of each bootstrap replicate (as coefficient_values: 0 where not
  // identifiable), for the intervals of what the model predicts. Not written to study.json.
  std::vector<std::vector<double>> replicates;
};

// Which coefficients can be fitted to these points: all but b when P never varies.
std::vector<bool> identifiable_terms(const CostModel& model,
                                     const std::vector<Measurement>& points);

// The coefficients fitted to `medians` (one per point), each weighted by 1/scale², so that
// the fit minimizes relative error; `scale` is the medians themselves when empty (a bootstrap
// replicate passes the measured medians: the weights are the design, not a resampled value).
Expected<std::vector<double>> fit_coefficients(const CostModel& model,
                                               const std::vector<Measurement>& points,
                                               const std::vector<double>& medians,
                                               const std::vector<bool>& use,
                                               const std::vector<double>& scale = {});

// The model fitted to the points' medians, its intervals from `boot` replicates of the
// bootstrap over repetitions, its quality and verdict against `limits`. Too few points, or
// terms that cannot be told apart, give fits = false with the reason, not an error.
ModelFit fit_model(const CostModel& model, const std::vector<Measurement>& points,
                   const BootstrapOptions& boot, const FitThresholds& limits = {});

// The models a form may be extended to for these points: the textbook form, + edges, + a
// knee at each measured N with at least two points on either side, + both.
std::vector<CostModel> candidate_models(const CostModel& textbook,
                                        const std::vector<Measurement>& points);

// The textbook form unless the data demand an extension: each more complex tier (one
// extension, then both) is taken when its best candidate lowers the mean leave-one-out error
// by limits.min_extension_gain; then fitted as fit_model does, `selection` saying why.
ModelFit fit_chosen_model(const CostModel& textbook, const std::vector<Measurement>& points,
                          const BootstrapOptions& boot, const FitThresholds& limits = {});

// The coefficients as fitted (b, when folded into a, as 0): for predict().
std::vector<double> coefficient_values(const ModelFit& fit);

// The fitted model's time of a frame of P pixels and axis value N (what charts draw).
double predict_seconds(const ModelFit& fit, double pixels, double n);

// What two fitted models predict for the ratio t_a / t_b at (P, N), and its 95% interval over
// their bootstrap replicates (replicate k of one with replicate k of the other). NaN when
// either does not fit or predicts no positive time there.
struct PredictedRatio {
  double ratio = 0;
  double low = 0, high = 0;
};
PredictedRatio predict_ratio(const ModelFit& a, const ModelFit& b, double pixels, double n);

}  // namespace rvr::study
