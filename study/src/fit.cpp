// Fitting a cost model with bootstrap intervals (see fit.h).
#include "rvr/study/fit.h"

#include <fmt/format.h>

#include <cmath>

#include "rvr/study/fit_quality.h"
#include "rvr/study/least_squares.h"

namespace rvr::study {
namespace {

// Every point's pixel count when they all share one, else 0.
double shared_pixels(const std::vector<Measurement>& points) {
  if (points.empty()) return 0;
  for (const Measurement& p : points)
    if (p.pixels != points[0].pixels) return 0;
  return points[0].pixels;
}

// Each coefficient's 95% interval over the bootstrap replicates (replicates whose fit fails,
// which terms that are independent in the data do not, are skipped).
std::vector<Interval> bootstrap_intervals(ModelForm form, const std::vector<Measurement>& points,
                                          const std::vector<bool>& use,
                                          const BootstrapOptions& boot) {
  Rng rng(boot.seed);
  std::vector<double> measured;
  for (const Measurement& p : points) measured.push_back(typical_seconds(p));
  std::vector<std::vector<double>> draws(use.size());
  for (int r = 0; r < boot.replicates; ++r) {
    Expected<std::vector<double>> c =
        fit_coefficients(form, points, resample_medians(points, rng), use, measured);
    if (!c) continue;
    for (size_t j = 0; j < use.size(); ++j) draws[j].push_back((*c)[j]);
  }
  std::vector<Interval> intervals;
  for (const auto& d : draws) intervals.push_back(percentile_interval(d));
  return intervals;
}

// "fits", or the first threshold the fit misses.
std::string verdict(const ModelFit& f, const FitThresholds& limits) {
  if (f.r2 < limits.min_r2) return fmt::format("does not fit: R² {:.3f} < {}", f.r2, limits.min_r2);
  if (f.max_rel_residual > limits.max_rel_residual)
    return fmt::format("does not fit: a point is {:.0f}% off the model (limit {:.0f}%)",
                       100 * f.max_rel_residual, 100 * limits.max_rel_residual);
  if (!(f.loo_rel_error <= limits.max_loo_rel_error))
    return fmt::format("does not fit: points left out are predicted {:.0f}% off (limit {:.0f}%)",
                       100 * f.loo_rel_error, 100 * limits.max_loo_rel_error);
  return "fits";
}

}  // namespace

std::vector<bool> identifiable_terms(ModelForm form, const std::vector<Measurement>& points) {
  std::vector<bool> use(coefficient_names(form).size(), true);
  if (shared_pixels(points) > 0) use[kPixelCoefficient] = false;
  return use;
}

Expected<std::vector<double>> fit_coefficients(ModelForm form,
                                               const std::vector<Measurement>& points,
                                               const std::vector<double>& medians,
                                               const std::vector<bool>& use,
                                               const std::vector<double>& scale) {
  std::vector<std::vector<double>> x;
  std::vector<double> w;
  for (size_t i = 0; i < points.size(); ++i) {
    x.push_back(features(form, points[i].pixels, points[i].n));
    double s = scale.empty() ? medians[i] : scale[i];
    w.push_back(1.0 / (s * s));
  }
  return weighted_least_squares(x, medians, w, use);
}

ModelFit fit_model(ModelForm form, const std::vector<Measurement>& points,
                   const BootstrapOptions& boot, const FitThresholds& limits) {
  ModelFit f;
  f.form = form;
  f.formula = formula(form);
  f.points = points.size();
  f.fixed_pixels = shared_pixels(points);
  std::vector<bool> use = identifiable_terms(form, points);
  std::vector<double> medians;
  for (const Measurement& p : points) medians.push_back(typical_seconds(p));
  size_t used = 0;
  for (bool u : use) used += u;
  std::vector<std::string> names = coefficient_names(form);
  f.coefficients.resize(names.size());
  for (size_t j = 0; j < names.size(); ++j) {
    f.coefficients[j].name = names[j];
    f.coefficients[j].identifiable = use[j];
  }
  if (points.size() < used + 2) {
    f.verdict = fmt::format("does not fit: {} points for {} coefficients (at least {} needed)",
                            points.size(), used, used + 2);
    return f;
  }
  Expected<std::vector<double>> c = fit_coefficients(form, points, medians, use);
  if (!c) {
    f.verdict = "does not fit: " + c.error().message;
    return f;
  }
  std::vector<Interval> ci = bootstrap_intervals(form, points, use, boot);
  for (size_t j = 0; j < use.size(); ++j) {
    f.coefficients[j].value = (*c)[j];
    f.coefficients[j].ci95 = ci[j];
  }
  FitQuality q = fit_quality(form, points, medians, *c, use);
  f.r2 = q.r2;
  f.max_rel_residual = q.max_rel_residual;
  f.loo_rel_error = q.loo_rel_error;
  f.verdict = verdict(f, limits);
  f.fits = f.verdict == "fits";
  return f;
}

std::vector<double> coefficient_values(const ModelFit& fit) {
  std::vector<double> v;
  for (const Coefficient& c : fit.coefficients) v.push_back(c.identifiable ? c.value : 0.0);
  return v;
}

double predict_seconds(const ModelFit& fit, double pixels, double n) {
  return predict(fit.form, coefficient_values(fit), pixels, n);
}

}  // namespace rvr::study
