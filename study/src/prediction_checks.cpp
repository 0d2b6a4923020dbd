// Crossovers checked out of sample (see prediction_checks.h).
#include "rvr/study/prediction_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "rvr/study/bootstrap.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"

namespace rvr::study {
namespace {

constexpr double kCheckFactor = 3.0;
// A check point within this factor of a point already measured is moved off it by it.
constexpr double kOffGrid = 1.15;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The measured point of `scene` at full width nearest `at` along N.
const Measurement* nearest_along_n(const StudyResult& r, const std::string& scene, double at) {
  const Measurement* nearest = nullptr;
  for (const Measurement& m : r.points)
    if (m.scene == scene && m.n > 0 && m.width == r.width &&
        (!nearest || std::fabs(std::log(m.n / at)) < std::fabs(std::log(nearest->n / at))))
      nearest = &m;
  return nearest;
}

// Whether (scene_n, width) lies within kOffGrid of a point of the sweep.
bool on_grid(const StudyResult& r, const std::string& scene, double scene_n, int width) {
  for (const Measurement& m : r.points)
    if (m.scene == scene && std::fabs(std::log(m.scene_n / scene_n)) < std::log(kOffGrid) &&
        std::fabs(std::log(double(m.width) / double(width))) < std::log(kOffGrid))
      return true;
  return false;
}

// The scene N of the check at axis value `at` along N, off the grid.
size_t check_n(const StudyResult& r, const Crossover& c, double at) {
  const Measurement* nearest = nearest_along_n(r, c.scene, at);
  if (!nearest) return 0;
  double n = std::max(1.0, std::round(nearest->scene_n * at / nearest->n));
  if (on_grid(r, c.scene, n, r.width)) n = std::round(n * kOffGrid);
  return size_t(n);
}

// The width of the check at pixel count `at` along the pixel axis (height 3/4 of it), off the
// grid, in 16 … 16384, a multiple of 4.
int check_width(const StudyResult& r, const Crossover& c, double scene_n, double at) {
  auto round4 = [](double w) { return std::clamp(4 * int(std::lround(w / 4)), 16, 16384); };
  int width = round4(std::sqrt(at * 4.0 / 3.0));
  if (on_grid(r, c.scene, scene_n, width)) width = round4(width * kOffGrid);
  return width;
}

// The scene N of the column a pixel-axis crossover was found in.
double column_scene_n(const StudyResult& r, const Crossover& c) {
  for (const Measurement& m : r.points)
    if (m.scene == c.scene && m.n == c.n) return m.scene_n;
  return 0;
}

// The axis values a crossover is checked at.
std::vector<double> check_values(const Crossover& c) {
  if (c.measured) return {c.value / kCheckFactor, c.value * kCheckFactor};
  const bool above = c.value > c.range_high;
  return {c.value, above ? c.value * kCheckFactor : c.value / kCheckFactor};
}

const Measurement* find(const std::vector<Measurement>& points, const std::string& renderer,
                        const CheckPoint& p) {
  for (const Measurement& m : points)
    if (m.renderer == renderer && m.scene == p.scene && size_t(m.scene_n) == p.scene_n &&
        m.width == p.width)
      return &m;
  return nullptr;
}

const ModelFit* fit_of(const StudyResult& r, const std::string& renderer,
                       const std::string& scene) {
  for (const RendererModels& m : r.models)
    if (m.name == renderer)
      if (auto it = m.fits.find(scene); it != m.fits.end()) return &it->second;
  return nullptr;
}

// The spread of the sweep's own points in the comparison the crossover came from (their runs'
// log-ratio spread is a floor for a check point's, measured in as few sessions), and the noise
// between its points.
struct SweepNoise {
  double point_noise = 0;
};

SweepNoise sweep_noise(const StudyResult& r, const Crossover& c) {
  for (const Comparison& x : r.comparisons)
    if (x.a == c.a && x.b == c.b && x.scene == c.scene && x.axis == c.axis &&
        x.pixels == c.pixels && x.n == c.n)
      return {x.point_noise};
  return {};
}

// The standard normal's upper tail.
double upper_tail(double z) {
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

// One check measured: its ratio, interval and the unadjusted p-value of the side it lies on.
struct Measured {
  double d = kNaN, sd = 0;
  Interval ci{kNaN, kNaN};
  double p = 1;
};

Measured measure_ratio(const Measurement& a, const Measurement& b, const CompareOptions& o) {
  Measured out;
  PairedRatios pr = paired_ratios(a, b);
  if (pr.runs.empty()) return out;
  out.d = ratio_estimate(pr);
  Rng rng(o.boot.seed ^ 0xc4ec);
  std::vector<double> draws;
  for (int k = 0; k < std::max(o.boot.replicates, 100); ++k)
    draws.push_back(resample_ratio(pr, rng));
  // A bootstrap over three runs sees two thirds of their variance: corrected by n/(n−1).
  const double runs = double(pr.runs.size());
  out.sd = std::sqrt(variance(draws) * (runs > 1 ? runs / (runs - 1) : 1.0));
  Interval ci = percentile_interval(draws);
  out.ci = {std::exp(ci.low), std::exp(ci.high)};
  const double delta = std::log1p(o.noise_threshold);
  if (out.sd > 0) {
    const double below = upper_tail((-delta - out.d) / out.sd);
    const double above = upper_tail((out.d - delta) / out.sd);
    out.p = std::min(1.0, 2 * std::min(below, above));
  } else {
    out.p = std::fabs(out.d) > delta ? 0.0 : 1.0;
  }
  return out;
}

std::string ratio_text(double ratio) {
  return ratio >= 1 ? fmt::format("{:.2f}× slower", ratio)
                    : fmt::format("{:.2f}× faster", 1 / ratio);
}

// The verdict of one check from what was predicted and measured.
void judge(PredictionCheck& check, double point_noise) {
  const bool side_predicted = !check.predicted_faster.empty();
  const bool side_measured = !check.measured_faster.empty();
  const bool has_model = std::isfinite(check.predicted_ratio);
  // The models predict the curve; a point strays from it by the noise between points.
  const double spread = std::exp(2 * point_noise);
  const bool model_agrees =
      !has_model || (check.ratio_ci95.high >= check.predicted_ci95.low / spread &&
                     check.ratio_ci95.low <= check.predicted_ci95.high * spread);
  if (side_predicted && side_measured && check.measured_faster != check.predicted_faster) {
    check.verdict = "fails";
    check.why = fmt::format("{} was measured faster, significantly, where {} should be",
                            check.measured_faster, check.predicted_faster);
  } else if (!model_agrees) {
    check.verdict = "fails";
    check.why = fmt::format(
        "the models predicted t({}) / t({}) = {:.2f} (95%: {:.2f} – {:.2f}); measured {:.2f} "
        "(95%: {:.2f} – {:.2f})",
        check.a, check.b, check.predicted_ratio, check.predicted_ci95.low,
        check.predicted_ci95.high, check.ratio, check.ratio_ci95.low, check.ratio_ci95.high);
  } else if (side_predicted && side_measured) {
    check.verdict = "holds";
    check.why = fmt::format("{} is faster, as predicted ({} {})", check.measured_faster, check.a,
                            ratio_text(check.ratio));
  } else if (!side_predicted && has_model) {
    check.verdict = "holds";
    check.why =
        fmt::format("the measured ratio {:.2f} lies within the models' prediction", check.ratio);
  } else {
    check.verdict = "inconclusive";
    check.why = fmt::format("the measured ratio {:.2f} is within the noise threshold", check.ratio);
  }
}

}  // namespace

std::vector<CheckPoint> plan_checks(const StudyResult& r) {
  std::vector<CheckPoint> out;
  for (size_t i = 0; i < r.crossovers.size(); ++i) {
    const Crossover& c = r.crossovers[i];
    for (double at : check_values(c)) {
      CheckPoint p{i, c.scene, 0, r.width};
      if (c.axis == kPixelsAxis) {
        const double scene_n = column_scene_n(r, c);
        if (scene_n <= 0) continue;
        p.scene_n = size_t(scene_n);
        p.width = check_width(r, c, scene_n, at);
      } else {
        p.scene_n = check_n(r, c, at);
      }
      if (p.scene_n > 0) out.push_back(p);
    }
  }
  return out;
}

void evaluate_checks(StudyResult& r, const CompareOptions& options) {
  r.checks.clear();
  std::vector<double> p;
  for (const CheckPoint& point : plan_checks(r)) {
    const Crossover& c = r.crossovers[point.crossover];
    const Measurement *a = find(r.check_points, c.a, point), *b = find(r.check_points, c.b, point);
    if (!a || !b) continue;
    const Measured m = measure_ratio(*a, *b, options);
    if (std::isnan(m.d)) continue;
    PredictionCheck check;
    check.a = c.a;
    check.b = c.b;
    check.scene = c.scene;
    check.axis = c.axis;
    check.crossover = c.value;
    check.extrapolated = !c.measured;
    check.at = c.axis == kPixelsAxis ? a->pixels : a->n;
    check.pixels = a->pixels;
    check.n = a->n;
    const double distance = std::log(check.at / c.value);
    if (std::fabs(distance) > std::log(1.5))
      check.predicted_faster = (distance < 0) == c.a_faster_below ? c.a : c.b;
    check.ratio = std::exp(m.d);
    check.ratio_ci95 = m.ci;
    const ModelFit *fa = fit_of(r, c.a, c.scene), *fb = fit_of(r, c.b, c.scene);
    PredictedRatio predicted{kNaN, kNaN, kNaN};
    if (fa && fb) predicted = predict_ratio(*fa, *fb, a->pixels, a->n);
    check.predicted_ratio = predicted.ratio;
    check.predicted_ci95 = {predicted.low, predicted.high};
    p.push_back(m.p);
    r.checks.push_back(check);
  }
  const std::vector<double> adjusted = holm_adjusted(p);
  for (size_t k = 0; k < r.checks.size(); ++k) {
    PredictionCheck& check = r.checks[k];
    check.p = adjusted[k];
    if (check.p <= kFamilyAlpha) check.measured_faster = check.ratio < 1 ? check.a : check.b;
    double point_noise = 0;
    for (const Crossover& c : r.crossovers)
      if (c.a == check.a && c.b == check.b && c.scene == check.scene && c.axis == check.axis &&
          c.value == check.crossover)
        point_noise = sweep_noise(r, c).point_noise;
    judge(check, point_noise);
  }
  for (Crossover& c : r.crossovers)
    for (const PredictionCheck& check : r.checks)
      if (check.verdict == "fails" && c.a == check.a && c.b == check.b && c.scene == check.scene &&
          c.axis == check.axis && c.value == check.crossover)
        c.contradicted = true;
}

}  // namespace rvr::study
