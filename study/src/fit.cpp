// Fitting a cost model with bootstrap intervals (see fit.h).
#include "rvr/study/fit.h"

#include <fmt/format.h>

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <initializer_list>
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

std::vector<double> weights_of(const std::vector<double>& times) {
  std::vector<double> w;
  w.reserve(times.size());
  for (double t : times) w.push_back(1.0 / (t * t));
  return w;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) s += a[i] * b[i];
  return s;
}

// The variance of log typical_seconds(m) from its runs alone: the sample variance of the log of
// each timed run's Harrell–Davis median over their count (unbiased whatever the split between
// the noise of frames and of sessions); NaN with fewer than two runs.
double between_run_variance(const Measurement& m) {
  std::vector<double> logs;
  for (const Run* r : timed_runs(m)) logs.push_back(std::log(hd_median(r->seconds)));
  if (logs.size() < 2) return std::numeric_limits<double>::quiet_NaN();
  return variance(logs) / double(logs.size());
}

}  // namespace

double timing_noise(const std::vector<Measurement>& points) {
  double sum = 0;
  size_t count = 0;
  for (const Measurement& m : points) {
    double v = between_run_variance(m);
    if (!std::isfinite(v)) {
      // One run: the variance of the log of its frames over their number.
      std::vector<double> logs;
      for (const Run* r : timed_runs(m))
        for (double t : r->seconds) logs.push_back(std::log(t));
      v = logs.empty() ? 0.0 : variance(logs) / double(logs.size());
    }
    sum += v;
    ++count;
  }
  return count ? std::sqrt(sum / double(count)) : 0.0;
}

std::string fit_verdict(const FitQuality& q, const FitThresholds& limits) {
  if (q.r2 < limits.min_r2) return fmt::format("does not fit: R² {:.3f} < {}", q.r2, limits.min_r2);
  if (q.max_rel_residual > limits.max_rel_residual)
    return fmt::format("does not fit: a point is {:.0f}% off the model (limit {:.0f}%)",
                       100 * q.max_rel_residual, 100 * limits.max_rel_residual);
  if (!(q.loo_median_rel_error <= limits.max_loo_rel_error))
    return fmt::format("does not fit: points left out are predicted {:.0f}% off (limit {:.0f}%)",
                       100 * q.loo_median_rel_error, 100 * limits.max_loo_rel_error);
  return "fits";
}

std::vector<bool> identifiable_terms(const CostModel& model,
                                     const std::vector<Measurement>& points) {
  std::vector<bool> use(coefficient_names(model).size(), true);
  if (shared_pixels(points) > 0) use[kPixelCoefficient] = false;
  return use;
}

std::vector<std::vector<double>> design_rows(const CostModel& model,
                                             const std::vector<Measurement>& points) {
  std::vector<std::vector<double>> rows;
  rows.reserve(points.size());
  for (const Measurement& p : points) rows.push_back(features(model, p.pixels, p.n));
  return rows;
}

Expected<std::vector<double>> fit_rows(const std::vector<std::vector<double>>& rows,
                                       const std::vector<double>& times,
                                       const std::vector<bool>& use,
                                       const std::vector<double>& scale) {
  return nonnegative_least_squares(rows, times, weights_of(scale.empty() ? times : scale), use);
}

Expected<std::vector<double>> fit_coefficients(const CostModel& model,
                                               const std::vector<Measurement>& points,
                                               const std::vector<double>& medians,
                                               const std::vector<bool>& use,
                                               const std::vector<double>& scale) {
  return fit_rows(design_rows(model, points), medians, use, scale);
}

Expected<LinearFit> fit_linear(const std::vector<std::vector<double>>& rows,
                               const std::vector<Measurement>& points, const std::vector<bool>& use,
                               const BootstrapOptions& boot) {
  const size_t n = points.size();
  std::vector<double> times;
  times.reserve(n);
  for (const Measurement& p : points) times.push_back(typical_seconds(p));
  RVR_TRY_ASSIGN(fitted, fit_rows(rows, times, use));
  LinearFit out;
  out.values = *fitted;
  out.quality = fit_quality(rows, times, out.values, use);

  // The scatter about the model: relative residuals over the degrees of freedom left by the
  // coefficients the fit uses (one held at 0 by its constraint is not one of them).
  size_t active = 0;
  for (size_t j = 0; j < use.size(); ++j) active += use[j] && out.values[j] > 0;
  std::vector<double> model(n);
  double rss = 0;
  for (size_t i = 0; i < n; ++i) {
    model[i] = dot(rows[i], out.values);
    const double e = (times[i] - model[i]) / times[i];
    rss += e * e;
  }
  const size_t dof = n > active ? n - active : 0;
  const double scatter = dof > 0 ? rss / double(dof) : 0.0;

  // The repetitions' replicates (relative to the measured times), their variance summed over the
  // points, and the unbiased variance from the runs alone.
  Rng rng(boot.seed);
  const size_t count = size_t(std::max(boot.replicates, 0));
  std::vector<std::vector<double>> noise(count, std::vector<double>(n));
  for (size_t r = 0; r < count; ++r) {
    const std::vector<double> t = resample_times(points, rng);
    for (size_t i = 0; i < n; ++i) noise[r][i] = t[i] / times[i] - 1;
  }
  double resampled = 0, between = 0;
  bool every_point_has_runs = true;
  for (size_t i = 0; i < n; ++i) {
    std::vector<double> column(count);
    for (size_t r = 0; r < count; ++r) column[r] = noise[r][i];
    resampled += variance(column);
    const double v = between_run_variance(points[i]);
    every_point_has_runs = every_point_has_runs && std::isfinite(v);
    between += std::isfinite(v) ? v : 0.0;
  }
  // Drawing sessions and then rounds counts the frames' noise at both levels (too wide when
  // frames vary more than sessions) and sees only the sessions drawn (too narrow when sessions
  // vary more): its replicates are scaled to the runs' own variance, pooled over the points.
  const double scale = every_point_has_runs && resampled > 0 ? std::sqrt(between / resampled) : 1.0;
  const double noise_variance = n > 0 ? scale * scale * resampled / double(n) : 0.0;
  out.repetition_noise = std::sqrt(noise_variance);
  out.misfit = std::sqrt(std::max(0.0, scatter - noise_variance));
  // That scatter is estimated from `dof` residuals: its normal draws are widened by the ratio of
  // Student's t quantile to the normal one, as a t interval is wider than a z interval.
  double widen = 1;
  if (dof > 0) {
    const boost::math::students_t t{double(dof)};
    widen = boost::math::quantile(t, 0.975) / boost::math::quantile(boost::math::normal{}, 0.975);
  }

  // Replicates whose fit fails (which terms independent in the data do not) are skipped.
  std::vector<std::vector<double>> draws(use.size());
  std::vector<double> y(n);
  for (size_t r = 0; r < count; ++r) {
    for (size_t i = 0; i < n; ++i)
      y[i] = model[i] + times[i] * (scale * noise[r][i] + widen * out.misfit * rng.normal());
    Expected<std::vector<double>> c = fit_rows(rows, y, use, times);
    if (!c) continue;
    for (size_t j = 0; j < use.size(); ++j) draws[j].push_back((*c)[j]);
    out.replicates.push_back(*c);
  }
  for (const auto& d : draws) out.ci95.push_back(percentile_interval(d));
  return out;
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
  Expected<LinearFit> fit = fit_linear(design_rows(model, points), points, use, boot);
  if (!fit) {
    f.verdict = "does not fit: " + fit.error().message;
    return f;
  }
  for (size_t j = 0; j < use.size(); ++j) {
    f.coefficients[j].value = fit->values[j];
    f.coefficients[j].ci95 = fit->ci95[j];
  }
  take_fit(f, *fit, limits);
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
  auto with = [&](bool edges, double knee, bool flatter) {
    CostModel m = textbook;
    m.edges = edges;
    m.knee = knee;
    m.flatter = flatter;
    return m;
  };
  std::vector<CostModel> out = {with(false, 0, false), with(true, 0, false)};
  for (bool edges : {false, true})
    for (bool flatter : {false, true})
      for (size_t i = 2; i + 2 < ns.size(); ++i) out.push_back(with(edges, ns[i], flatter));
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
    double loo = leave_one_out(design_rows(m, points), medians, identifiable_terms(m, points))
                     .loo_mean_rel_error;
    auto& tier = best[size_t(extensions(m))];
    if (loo < tier.second) tier = {m, loo};
  }
  const double floor = limits.extension_noise_floor * timing_noise(points);
  size_t chosen = 0;
  for (size_t t = 1; t < best.size(); ++t)
    if (best[chosen].second > floor &&
        best[t].second < (1 - limits.min_extension_gain) * best[chosen].second)
      chosen = t;
  ModelFit f = fit_model(best[chosen].first, points, boot, limits);
  if (chosen > 0)
    f.selection = fmt::format(
        "extended: mean leave-one-out error {:.1f}% against {:.1f}% for the textbook form",
        100 * best[chosen].second, 100 * best[0].second);
  else if (best[0].second <= floor)
    f.selection = fmt::format(
        "the textbook form: its mean leave-one-out error ({:.1f}%) is within {}× the points' "
        "timing noise ({:.1f}%)",
        100 * best[0].second, limits.extension_noise_floor,
        100 * floor / limits.extension_noise_floor);
  else
    f.selection = fmt::format(
        "the textbook form: no extension lowered the mean leave-one-out error by {:.0f}%",
        100 * limits.min_extension_gain);
  return f;
}

}  // namespace rvr::study
