// A cost model fitted to a renderer's sweep: non-negative weighted least squares on relative
// error, 95% intervals from a bootstrap that holds both the repetitions' noise and the points'
// scatter about the model, and whether the model fits at all.
#pragma once

#include <stddef.h>

#include <string>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/fit_quality.h"
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
  // An extension is taken only when it lowers the mean leave-one-out error by this fraction,
  double min_extension_gain = 0.20;
  // and only when the model before it predicts the points left out worse than their timing
  // noise explains: its mean leave-one-out error above this many times timing_noise(). A
  // correct model's is about 0.9× (the mean absolute value of a normal error, a little more
  // for points at the ends of the sweep); below that bar the choice among many knees would
  // follow the noise.
  double extension_noise_floor = 1.5;
};

struct ModelFit {
  CostModel model;
  std::string formula;    // the model fitted, with any extension the data demanded
  std::string selection;  // why this model and not the textbook form or another extension
  std::vector<Coefficient> coefficients;
  double r2 = 0;                // weighted (1/t²) coefficient of determination
  double max_rel_residual = 0;  // largest |t − model| / t over the points
  double loo_rel_error = 0;     // median over the points of their error when left out
  // The points' relative scatter about the model beyond their timing noise, and that noise
  // (LinearFit): a misfit larger than the noise widens the intervals.
  double misfit = 0, repetition_noise = 0;
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

// Each point's features under `model` (features(model, P, N)): the rows of its fit.
std::vector<std::vector<double>> design_rows(const CostModel& model,
                                             const std::vector<Measurement>& points);

// The non-negative coefficients fitting `times` (one per row) with each row weighted by
// 1/scale², so that the fit minimizes relative error; `scale` is the times themselves when
// empty (a bootstrap replicate passes the measured times: the weights are the design, not a
// resampled value). nonnegative_least_squares (least_squares.h) does the work.
Expected<std::vector<double>> fit_rows(const std::vector<std::vector<double>>& rows,
                                       const std::vector<double>& times,
                                       const std::vector<bool>& use,
                                       const std::vector<double>& scale = {});

// fit_rows with the rows of a cost model.
Expected<std::vector<double>> fit_coefficients(const CostModel& model,
                                               const std::vector<Measurement>& points,
                                               const std::vector<double>& medians,
                                               const std::vector<bool>& use,
                                               const std::vector<double>& scale = {});

// A linear model (a cost model's features, or counted work) fitted to the points' times t_i
// (typical_seconds) by fit_rows, with 95% intervals from `boot.replicates` replicates that each
// refit, for every point,
//   y*_i = ŷ_i + t_i·(κ·m*_i + w·σ·z_i)
// ŷ_i the fitted time; m*_i = t*_i / t_i − 1, t*_i the point's hierarchical resample over its
// repetitions (resample_time: sessions, then rounds); z_i standard normal. Two sources of error:
//   - the repetitions' (timing noise): m*. Drawing sessions and then rounds counts the frames'
//     noise at both levels and sees only the sessions drawn, so κ² scales the replicates'
//     variance, summed over the points, to the unbiased one from the runs alone (the sample
//     variance of the log of each run's Harrell–Davis median, over the run count): κ = 1 when
//     any point has a single run;
//   - the points' scatter about the model beyond that noise: σ² = max(0, s² − κ²·mean var m*),
//     s² = Σ ((t_i − ŷ_i)/t_i)² / (points − coefficients fitted non-zero), the scatter the fit's
//     1/t² weights assume is the same at every point. It holds variation between scene sizes
//     that every run of a point repeats and the model's own error: a model that misses its
//     points has intervals as wide as the misfit even when every repetition is the same. w, the
//     97.5% quantile of Student's t with that many degrees of freedom over the normal one, widens
//     the draws for σ being estimated from few points.
struct LinearFit {
  std::vector<double> values;  // as fitted; 0 where not used
  std::vector<Interval> ci95;
  std::vector<std::vector<double>> replicates;  // each replicate's coefficients
  FitQuality quality;
  double misfit = 0;            // σ: the relative scatter about the model beyond the noise
  double repetition_noise = 0;  // κ·√(mean var m*): the relative timing noise of a point
};
Expected<LinearFit> fit_linear(const std::vector<std::vector<double>>& rows,
                               const std::vector<Measurement>& points, const std::vector<bool>& use,
                               const BootstrapOptions& boot);

// The points' relative timing noise: the root mean square over the points of the standard error
// of log typical_seconds from its runs (from its frames when it has one run).
double timing_noise(const std::vector<Measurement>& points);

// "fits", or the first of `limits` the fit misses, in words.
std::string fit_verdict(const FitQuality& q, const FitThresholds& limits);

// A fitted model (ModelFit, WorkModel) takes `fit`'s replicates, quality, misfit and noise, and
// its verdict against `limits`.
template <class Model>
void take_fit(Model& model, LinearFit& fit, const FitThresholds& limits) {
  model.replicates = std::move(fit.replicates);
  model.r2 = fit.quality.r2;
  model.max_rel_residual = fit.quality.max_rel_residual;
  model.loo_rel_error = fit.quality.loo_median_rel_error;
  model.misfit = fit.misfit;
  model.repetition_noise = fit.repetition_noise;
  model.verdict = fit_verdict(fit.quality, limits);
  model.fits = model.verdict == "fits";
}

// The model fitted to the points' times by fit_linear, its quality and verdict against
// `limits`. Too few points, or
// terms that cannot be told apart, give fits = false with the reason, not an error.
ModelFit fit_model(const CostModel& model, const std::vector<Measurement>& points,
                   const BootstrapOptions& boot, const FitThresholds& limits = {});

// The models a form may be extended to for these points: the textbook form, + edges, + a
// knee (steeper or flatter) at each measured N with at least two points on either side, + both.
std::vector<CostModel> candidate_models(const CostModel& textbook,
                                        const std::vector<Measurement>& points);

// The textbook form unless the data demand an extension: each more complex tier (one
// extension, then both) is taken when its best candidate lowers the mean leave-one-out error
// by limits.min_extension_gain and the tier before misses the points by more than their
// timing noise (limits.extension_noise_floor); then fitted as fit_model does, `selection`
// saying why.
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
