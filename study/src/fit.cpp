// Fitting a cost model with bootstrap intervals (see fit.h).
#include "rvr/study/fit.h"

#include <fmt/format.h>

#include <limits>
#include <memory>
#include <set>
#include <utility>

#include "rvr/study/fit_quality.h"
#include "rvr/study/least_squares.h"

namespace rvr::study {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Every point's pixel count when they all share one, else 0.
double shared_pixels(const std::vector<Measurement>& points) {
  if (points.empty()) return 0;
  for (const Measurement& p : points)
    if (p.pixels != points[0].pixels) return 0;
  return points[0].pixels;
}

// Each coefficient's 95% interval over the bootstrap replicates (replicates whose fit fails,
// which terms that are independent in the data do not, are skipped).
std::vector<Interval> bootstrap_intervals(const CostModel& model,
                                          const std::vector<Measurement>& points,
                                          const std::vector<bool>& use,
                                          const BootstrapOptions& boot,
                                          std::vector<std::vector<double>>& replicates) {
  Rng rng(boot.seed);
  std::vector<double> measured;
  measured.reserve(points.size());
  for (const Measurement& p : points) measured.push_back(typical_seconds(p));
  std::vector<std::vector<double>> draws(use.size());
  for (int r = 0; r < boot.replicates; ++r) {
    Expected<std::vector<double>> c =
        fit_coefficients(model, points, resample_times(points, rng), use, measured);
    if (!c) continue;
    for (size_t j = 0; j < use.size(); ++j) draws[j].push_back((*c)[j]);
    replicates.push_back(*c);
  }
  std::vector<Interval> intervals;
  intervals.reserve(draws.size());
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

std::vector<bool> identifiable_terms(const CostModel& model,
                                     const std::vector<Measurement>& points) {
  std::vector<bool> use(coefficient_names(model).size(), true);
  if (shared_pixels(points) > 0) use[kPixelCoefficient] = false;
  return use;
}

Expected<std::vector<double>> fit_coefficients(const CostModel& model,
                                               const std::vector<Measurement>& points,
                                               const std::vector<double>& medians,
                                               const std::vector<bool>& use,
                                               const std::vector<double>& scale) {
  std::vector<std::vector<double>> x;
  std::vector<double> w;
  for (size_t i = 0; i < points.size(); ++i) {
    x.push_back(features(model, points[i].pixels, points[i].n));
    double s = scale.empty() ? medians[i] : scale[i];
    w.push_back(1.0 / (s * s));
  }
  return weighted_least_squares(x, medians, w, use);
}

ModelFit fit_model(const CostModel& model, const std::vector<Measurement>& points,
                   const BootstrapOptions& boot, const FitThresholds& limits) {
  ModelFit f;
  f.model = model;
  f.formula = formula(model);
  f.selection = model.extended() ? "as asked" : "the textbook form";
  f.points = points.size();
  f.fixed_pixels = shared_pixels(points);
  std::vector<bool> use = identifiable_terms(model, points);
  std::vector<double> medians;
  medians.reserve(points.size());
  for (const Measurement& p : points) medians.push_back(typical_seconds(p));
  size_t used = 0;
  for (bool u : use) used += u;
  std::vector<std::string> names = coefficient_names(model);
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
  Expected<std::vector<double>> c = fit_coefficients(model, points, medians, use);
  if (!c) {
    f.verdict = "does not fit: " + c.error().message;
    return f;
  }
  std::vector<Interval> ci = bootstrap_intervals(model, points, use, boot, f.replicates);
  for (size_t j = 0; j < use.size(); ++j) {
    f.coefficients[j].value = (*c)[j];
    f.coefficients[j].ci95 = ci[j];
  }
  FitQuality q = fit_quality(model, points, medians, *c, use);
  f.r2 = q.r2;
  f.max_rel_residual = q.max_rel_residual;
  f.loo_rel_error = q.loo_median_rel_error;
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
  return predict(fit.model, coefficient_values(fit), pixels, n);
}

PredictedRatio predict_ratio(const ModelFit& a, const ModelFit& b, double pixels, double n) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  PredictedRatio out{nan, nan, nan};
  if (!a.fits || !b.fits) return out;
  const double ta = predict_seconds(a, pixels, n), tb = predict_seconds(b, pixels, n);
  if (!(ta > 0 && tb > 0)) return out;
  out.ratio = ta / tb;
  std::vector<double> ratios;
  const size_t count = std::min(a.replicates.size(), b.replicates.size());
  for (size_t k = 0; k < count; ++k) {
    const double ra = predict(a.model, a.replicates[k], pixels, n),
                 rb = predict(b.model, b.replicates[k], pixels, n);
    if (ra > 0 && rb > 0) ratios.push_back(ra / rb);
  }
  // Replicates predicting no positive time count as unbounded either way.
  for (size_t k = ratios.size(); k < count; ++k)
    ratios.push_back(k % 2 ? std::numeric_limits<double>::infinity() : 0.0);
  if (!ratios.empty()) {
    Interval ci = percentile_interval(ratios);
    out.low = ci.low, out.high = ci.high;
  }
  return out;
}

std::vector<CostModel> candidate_models(const CostModel& textbook,
                                        const std::vector<Measurement>& points) {
  std::set<double> distinct;
  for (const Measurement& p : points) distinct.insert(p.n);
  std::vector<double> ns(distinct.begin(), distinct.end());
  auto with = [&](bool edges, double knee) {
    CostModel m = textbook;
    m.edges = edges;
    m.knee = knee;
    return m;
  };
  std::vector<CostModel> out = {with(false, 0), with(true, 0)};
  for (size_t i = 2; i + 2 < ns.size(); ++i) out.push_back(with(false, ns[i]));
  for (size_t i = 2; i + 2 < ns.size(); ++i) out.push_back(with(true, ns[i]));
  return out;
}

ModelFit fit_chosen_model(const CostModel& textbook, const std::vector<Measurement>& points,
                          const BootstrapOptions& boot, const FitThresholds& limits) {
  std::vector<double> medians;
  medians.reserve(points.size());
  for (const Measurement& p : points) medians.push_back(typical_seconds(p));
  CostModel widest = textbook;
  widest.edges = true;
  widest.knee = 1;
  const size_t enough = coefficient_names(widest).size() + 2;
  auto extensions = [](const CostModel& m) { return int(m.edges) + int(m.knee > 0); };
  // The best candidate of each tier (number of extensions), by mean leave-one-out error.
  std::vector<std::pair<CostModel, double>> best(3, {textbook, kInfinity});
  for (const CostModel& m : candidate_models(textbook, points)) {
    if (m.extended() && points.size() < enough) continue;
    double loo =
        leave_one_out(m, points, medians, identifiable_terms(m, points)).loo_mean_rel_error;
    auto& tier = best[size_t(extensions(m))];
    if (loo < tier.second) tier = {m, loo};
  }
  size_t chosen = 0;
  for (size_t t = 1; t < best.size(); ++t)
    if (best[t].second < (1 - limits.min_extension_gain) * best[chosen].second) chosen = t;
  ModelFit f = fit_model(best[chosen].first, points, boot, limits);
  f.selection = chosen == 0 ? "the textbook form: no extension lowered the mean leave-one-out "
                              "error by " +
                                  fmt::format("{:.0f}%", 100 * limits.min_extension_gain)
                            : fmt::format(
                                  "extended: mean leave-one-out error {:.1f}% against {:.1f}% "
                                  "for the textbook form",
                                  100 * best[chosen].second, 100 * best[0].second);
  return f;
}

}  // namespace rvr::study
