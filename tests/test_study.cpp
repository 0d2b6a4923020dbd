// The study's statistics, tested as the renderers are: synthetic measurements from known cost
// models with known noise, recovered within their intervals; the intervals' coverage over
// seeded replicates; crossovers where the curves cross, or reported outside the swept range;
// and the whole sweep within its budget on a simulated clock.
//
// Planted bugs these tests were seen to catch (each planted, run, restored):
// - a pairs bootstrap (points drawn with replacement instead of each point's repetitions):
//   IntervalCoverageOverSeededReplicates (86% coverage) and
//   IdenticalRepetitionsGiveIntervalsOfNoWidth;
// - log2 of the pixels instead of the triangles in the tracer's model:
//   TracerFeaturesTakeTheLogOfTheTriangles, RecoversKnownCoefficientsWithinTheirIntervals,
//   IntervalCoverageOverSeededReplicates, OutsideTheSweptRangeIsReportedAsSuch.
// - study.html's escape_html returning its input: EscapesEveryStringFromTheData;
// - no interval band drawn for a crossover: MarksTheCrossoverWithItsInterval.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/least_squares.h"
#include "rvr/study/run_study.h"
#include "rvr/study/study_html.h"
#include "rvr/study/study_json.h"
#include "rvr/study/study_markdown.h"
#include "rvr/study/sweep_plan.h"

using namespace rvr;
using namespace rvr::study;

namespace {

using CostFn = std::function<double(double pixels, double n)>;

// Repetitions of a frame that costs `cost(P, N)`, each off by a log-normal factor of `sigma`.
Measurement synthetic(const std::string& renderer, const CostFn& cost, double pixels, double n,
                      int reps, double sigma, Rng& rng) {
  Measurement m;
  m.renderer = renderer;
  m.scene = "synthetic";
  m.scene_n = m.n = n;
  m.pixels = pixels;
  for (int k = 0; k < reps; ++k)
    m.seconds.push_back(cost(pixels, n) * std::exp(sigma * rng.normal()));
  return m;
}

// A sweep of 13 log-spaced N from 10^2 to 10^6 at each of the pixel counts.
std::vector<Measurement> sweep(const std::string& renderer, const CostFn& cost,
                               const std::vector<double>& pixel_counts, int reps, double sigma,
                               Rng& rng) {
  std::vector<Measurement> out;
  for (double p : pixel_counts)
    for (size_t n : log_spaced(100, 1000000, 13))
      out.push_back(synthetic(renderer, cost, p, double(n), reps, sigma, rng));
  return out;
}

CostFn model_cost(CostModel model, std::vector<double> c) {
  return [model, c](double p, double n) { return predict(model, c, p, n); };
}

// Known coefficients of the size the renderers have (seconds, per pixel, per triangle...).
const std::vector<double> kZBuffer = {2e-3, 8e-9, 40e-9};
const std::vector<double> kTracer = {1e-3, 20e-9, 6e-9};
const std::vector<double> kHybrid = {3e-3, 10e-9, 30e-9, 2e-9};
constexpr double kP = 1024.0 * 768;

bool covers(const Coefficient& c, double truth) {
  return c.ci95.low <= truth && truth <= c.ci95.high;
}

}  // namespace

TEST(StudyLeastSquares, SolvesAnExactSystem) {
  std::vector<std::vector<double>> x = {{1, 1}, {1, 2}, {1, 3}};
  std::vector<double> y = {3, 5, 7};  // 1 + 2x
  Expected<std::vector<double>> b = weighted_least_squares(x, y, {1, 1, 1}, {true, true});
  ASSERT_TRUE(b.ok());
  EXPECT_NEAR((*b)[0], 1.0, 1e-12);
  EXPECT_NEAR((*b)[1], 2.0, 1e-12);
  // A column repeating another is refused, not solved.
  EXPECT_FALSE(weighted_least_squares({{1, 2}, {1, 2}, {1, 2}}, y, {1, 1, 1}, {true, true}).ok());
}

TEST(StudyModel, TracerFeaturesTakeTheLogOfTheTriangles) {
  std::vector<double> x = features(ModelForm::Tracer, 1000.0, 1024.0);
  ASSERT_EQ(x.size(), 3u);
  EXPECT_DOUBLE_EQ(x[2], 1000.0 * 10.0);  // P · log2 N
}

// Every form, at two image sizes so that every coefficient can be told apart.
TEST(StudyFit, RecoversKnownCoefficientsWithinTheirIntervals) {
  Rng rng(7);
  const std::vector<double> pixels = {256.0 * 192, kP};
  for (auto [form, truth] :
       {std::pair{ModelForm::ZBuffer, kZBuffer}, std::pair{ModelForm::Tracer, kTracer},
        std::pair{ModelForm::Hybrid, kHybrid}}) {
    std::vector<Measurement> points = sweep("r", model_cost(form, truth), pixels, 5, 0.03, rng);
    ModelFit f = fit_model(form, points, {1000, 3});
    ASSERT_TRUE(f.fits) << to_string(form) << ": " << f.verdict;
    EXPECT_GT(f.r2, 0.99) << to_string(form);
    EXPECT_LT(f.max_rel_residual, 0.1) << to_string(form);
    EXPECT_LT(f.loo_rel_error, 0.1) << to_string(form);
    for (size_t j = 0; j < truth.size(); ++j) {
      EXPECT_TRUE(f.coefficients[j].identifiable);
      EXPECT_TRUE(covers(f.coefficients[j], truth[j]))
          << to_string(form) << " " << f.coefficients[j].name << " = " << truth[j] << " not in ["
          << f.coefficients[j].ci95.low << ", " << f.coefficients[j].ci95.high << "]";
    }
  }
}

// At one image size (what the command sweeps) b cannot be told from a: it is reported so, and
// a holds a + b·P.
TEST(StudyFit, OneImageSizeFoldsThePixelTermIntoTheConstant) {
  Rng rng(11);
  std::vector<Measurement> points =
      sweep("r", model_cost(ModelForm::ZBuffer, kZBuffer), {kP}, 5, 0.02, rng);
  ModelFit f = fit_model(ModelForm::ZBuffer, points, {500, 1});
  ASSERT_TRUE(f.fits) << f.verdict;
  EXPECT_FALSE(f.coefficients[kPixelCoefficient].identifiable);
  EXPECT_EQ(f.fixed_pixels, kP);
  EXPECT_TRUE(covers(f.coefficients[0], kZBuffer[0] + kZBuffer[1] * kP));
  EXPECT_TRUE(covers(f.coefficients[2], kZBuffer[2]));
}

// 200 seeded studies: the 95% intervals of the per-triangle and per-ray-and-level terms hold
// the true value in 90-98% of them.
TEST(StudyFit, IntervalCoverageOverSeededReplicates) {
  for (auto [form, truth] :
       {std::pair{ModelForm::ZBuffer, kZBuffer}, std::pair{ModelForm::Tracer, kTracer}}) {
    int covered = 0;
    const int replicates = 200;
    for (int i = 0; i < replicates; ++i) {
      Rng rng(1000 + i);
      std::vector<Measurement> points = sweep("r", model_cost(form, truth), {kP}, 5, 0.05, rng);
      ModelFit f = fit_model(form, points, {400, uint64_t(5000 + i)});
      covered += covers(f.coefficients[2], truth[2]);
    }
    double coverage = double(covered) / replicates;
    EXPECT_GE(coverage, 0.90) << to_string(form);
    EXPECT_LE(coverage, 0.98) << to_string(form);
  }
}

// The intervals are about timing noise, which only the repetitions show: with every repetition
// of a point the same, they have no width even where the model misses the points. (A bootstrap
// that resamples the points would give them the width of the misfit.)
TEST(StudyBootstrap, IdenticalRepetitionsGiveIntervalsOfNoWidth) {
  std::vector<Measurement> points;
  for (size_t n : log_spaced(100, 1000000, 9)) {
    Measurement m;
    m.renderer = "r";
    m.n = double(n);
    m.pixels = kP;
    double wobble = (points.size() % 2 ? 1.1 : 0.9);  // 10% off the line, alternately
    m.seconds.assign(5, (2e-3 + 40e-9 * double(n)) * wobble);
    points.push_back(m);
  }
  ModelFit f = fit_model(ModelForm::ZBuffer, points, {200, 1});
  for (const Coefficient& c : f.coefficients) {
    if (!c.identifiable) continue;
    EXPECT_EQ(c.ci95.low, c.value) << c.name;
    EXPECT_EQ(c.ci95.high, c.value) << c.name;
  }
}

// Each replicate keeps every point, in order, its median drawn from its own repetitions.
TEST(StudyBootstrap, ReplicatesResampleEachPointsOwnRepetitions) {
  std::vector<Measurement> points(6);
  for (size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < 5; ++k) points[i].seconds.push_back(double(i) + 0.1 * k);
  Rng rng(3);
  for (int r = 0; r < 50; ++r) {
    std::vector<double> m = resample_medians(points, rng);
    ASSERT_EQ(m.size(), points.size());
    for (size_t i = 0; i < m.size(); ++i) {
      EXPECT_GE(m[i], double(i));
      EXPECT_LE(m[i], double(i) + 0.4);
    }
  }
}

// Too few points, or a curve the model cannot follow, is said, not concluded from.
TEST(StudyFit, AModelThatDoesNotFitSaysSo) {
  Rng rng(5);
  CostFn quadratic = [](double, double n) { return 1e-3 + 1e-14 * n * n; };
  ModelFit f = fit_model(ModelForm::Tracer, sweep("r", quadratic, {kP}, 5, 0.02, rng), {200, 1});
  EXPECT_FALSE(f.fits);
  EXPECT_NE(f.verdict.find("does not fit"), std::string::npos) << f.verdict;
  std::vector<Measurement> two = sweep("r", quadratic, {kP}, 5, 0.02, rng);
  two.resize(2);
  EXPECT_FALSE(fit_model(ModelForm::ZBuffer, two, {100, 1}).fits);
}

// On data from the textbook forms, an extension is almost never taken: over 40 seeded studies
// at two image sizes with 5% noise, at most 4 take one.
TEST(StudyModelChoice, TextbookDataKeepTheTextbookForm) {
  for (auto [form, truth] :
       {std::pair{ModelForm::ZBuffer, kZBuffer}, std::pair{ModelForm::Tracer, kTracer}}) {
    int extended = 0;
    for (int i = 0; i < 40; ++i) {
      Rng rng(300 + i);
      std::vector<Measurement> points =
          sweep("r", model_cost(form, truth), {256.0 * 192, kP}, 5, 0.05, rng);
      extended += fit_chosen_model(form, points, {50, 1}).model.extended();
    }
    EXPECT_LE(extended, 4) << to_string(form);
  }
}

// A z-buffer whose triangles' edges cost e·√(P·N): the edge term is taken, its coefficient
// recovered within its interval, and the textbook form is said not to fit.
TEST(StudyModelChoice, AnEdgeTermInTheDataIsFound) {
  const std::vector<double> truth = {0.2e-3, 9e-9, 12e-9, 25e-9};
  CostFn cost = [&](double p, double n) {
    return truth[0] + truth[1] * p + truth[2] * n + truth[3] * std::sqrt(p * n);
  };
  Rng rng(17);
  std::vector<Measurement> points = sweep("r", cost, {256.0 * 192, 512.0 * 384, kP}, 5, 0.03, rng);
  EXPECT_FALSE(fit_model(ModelForm::ZBuffer, points, {100, 1}).fits);
  ModelFit f = fit_chosen_model(ModelForm::ZBuffer, points, {1000, 1});
  ASSERT_TRUE(f.fits) << f.verdict;
  EXPECT_TRUE(f.model.edges) << f.formula;
  EXPECT_EQ(f.model.knee, 0) << f.formula;
  ASSERT_EQ(f.coefficients.size(), 4u);
  EXPECT_EQ(f.coefficients[3].name, "e");
  EXPECT_TRUE(covers(f.coefficients[3], truth[3]))
      << f.coefficients[3].ci95.low << " " << f.coefficients[3].ci95.high;
  EXPECT_NE(f.selection.find("extended"), std::string::npos) << f.selection;
}

// A tracer whose cost per level steepens past N = 46416 (the working set leaving a cache): the
// cache term is taken with its knee at that N.
TEST(StudyModelChoice, AChangeOfSlopeIsFoundAtItsKnee) {
  const double knee = double(log_spaced(100, 1000000, 13)[7]);
  const std::vector<double> truth = {1e-3, 20e-9, 1.5e-9, 12e-9};
  CostFn cost = [&](double p, double n) {
    return truth[0] + p * (truth[1] + truth[2] * std::log2(n)) +
           truth[3] * p * std::max(0.0, std::log2(n / knee));
  };
  Rng rng(23);
  std::vector<Measurement> points = sweep("r", cost, {256.0 * 192, kP}, 5, 0.03, rng);
  ModelFit f = fit_chosen_model(ModelForm::Tracer, points, {500, 1});
  ASSERT_TRUE(f.fits) << f.verdict;
  EXPECT_EQ(f.model.knee, knee) << f.formula;
  EXPECT_FALSE(f.model.edges) << f.formula;
  ASSERT_EQ(f.coefficients.size(), truth.size());
  for (size_t j = 0; j < truth.size(); ++j)
    EXPECT_TRUE(covers(f.coefficients[j], truth[j]))
        << f.coefficients[j].name << " = " << truth[j] << " not in [" << f.coefficients[j].ci95.low
        << ", " << f.coefficients[j].ci95.high << "]";
}

namespace {

// softraster's and raytrace's costs crossing at a known N, on one curve each.
const CostFn kZCurve = [](double, double n) { return 2e-3 + 400e-9 * n; };
const CostFn kTCurve = [](double p, double n) { return 1e-3 + p * 0.5e-9 * std::log2(n); };

double true_crossing() {
  double lo = 1e2, hi = 1e6;
  for (int i = 0; i < 200; ++i) {
    double mid = std::sqrt(lo * hi);
    (kZCurve(kP, mid) < kTCurve(kP, mid) ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

TEST(StudyCrossover, PlacedWhereTheMeasuredCurvesCross) {
  Rng rng(21);
  std::vector<Measurement> z = sweep("softraster", kZCurve, {kP}, 5, 0.03, rng);
  std::vector<Measurement> t = sweep("raytrace", kTCurve, {kP}, 5, 0.03, rng);
  CurveComparison c = compare_curves(z, t, "triangles", {1000, 2});
  ASSERT_EQ(c.crossovers.size(), 1u);
  const Crossover& x = c.crossovers[0];
  const double truth = true_crossing();
  EXPECT_TRUE(x.measured);
  EXPECT_TRUE(x.a_faster_below);  // the z-buffer wins with few triangles
  EXPECT_LT(std::fabs(std::log10(x.value / truth)), 0.1) << x.value << " vs " << truth;
  EXPECT_LE(x.ci95.low, truth);
  EXPECT_GE(x.ci95.high, truth);
  EXPECT_FALSE(c.dominance.has_value());
}

// Two renderers of the same cost, timed with 5% noise: their measured curves cross many times,
// but none of those crossings is beyond the noise: no crossover, a tie. 30% apart, one wins.
TEST(StudyCrossover, NoiseAloneMakesNoCrossover) {
  Rng rng(31);
  std::vector<Measurement> z = sweep("softraster", kZCurve, {kP}, 5, 0.05, rng);
  std::vector<Measurement> same = sweep("raytrace", kZCurve, {kP}, 5, 0.05, rng);
  CurveComparison tie = compare_curves(z, same, "triangles", {1000, 2});
  EXPECT_TRUE(tie.crossovers.empty())
      << tie.crossovers.size() << " crossovers, first at " << tie.crossovers[0].value;
  EXPECT_TRUE(tie.tie);
  const CostFn slower = [](double p, double n) { return 1.3 * kZCurve(p, n); };
  CurveComparison apart =
      compare_curves(z, sweep("raytrace", slower, {kP}, 5, 0.05, rng), "triangles", {1000, 2});
  EXPECT_TRUE(apart.crossovers.empty());
  ASSERT_TRUE(apart.dominance.has_value());
  EXPECT_EQ(apart.dominance->faster, "softraster");
  EXPECT_GT(apart.dominance->min_ratio, 1.1);
}

// Measured up to 2000 only, raytrace never catches up: softraster wins over the whole range,
// and the fitted models' crossover is reported as outside it, not as measured.
TEST(StudyCrossover, OutsideTheSweptRangeIsReportedAsSuch) {
  Rng rng(8);
  StudyResult r;
  r.scenes = {"synthetic"};
  r.renderers = {"softraster", "raytrace"};
  r.axes["synthetic"] = "triangles";
  r.width = 1024;
  r.height = 768;
  for (size_t n : log_spaced(100, 2000, 7)) {
    r.points.push_back(synthetic("softraster", kZCurve, kP, double(n), 5, 0.02, rng));
    r.points.push_back(synthetic("raytrace", kTCurve, kP, double(n), 5, 0.02, rng));
  }
  conclude(r, {300, 1});
  ASSERT_EQ(r.dominance.size(), 1u);
  EXPECT_EQ(r.dominance[0].faster, "softraster");
  EXPECT_GT(r.dominance[0].min_ratio, 1.0);
  ASSERT_EQ(r.crossovers.size(), 1u);
  const Crossover& x = r.crossovers[0];
  EXPECT_FALSE(x.measured);
  EXPECT_GT(x.value, x.range_high);
  EXPECT_LT(std::fabs(std::log10(x.value / true_crossing())), 0.15);
  std::string md = study_markdown(r);
  EXPECT_NE(md.find("outside the swept range"), std::string::npos) << md;
  EXPECT_NE(md.find("over the whole swept range"), std::string::npos) << md;
}

namespace {

// Frames whose cost comes from the curves above, on a clock that only they (and preparing,
// 1 µs a triangle) advance.
class SimulatedFrames : public FrameSource {
 public:
  SimulatedFrames(double n, int width, double& clock, Rng& rng)
      : n_(n), pixels_(double(width) * (width * 3 / 4)), clock_(clock), rng_(rng) {
    clock_ += 1e-6 * n;
  }
  double axis_value() const override { return n_; }
  double pixels() const override { return pixels_; }
  Expected<double> time_frame(size_t index) override {
    double t = (index == 0 ? kZCurve : kTCurve)(pixels_, n_) * std::exp(0.03 * rng_.normal());
    clock_ += t;
    return t;
  }

 private:
  double n_, pixels_;
  double& clock_;
  Rng& rng_;
};

}  // namespace

TEST(StudyRun, SweepsWithinTheBudgetAndRefinesNearTheCrossover) {
  double clock = 0;
  Rng rng(4);
  StudyRequest request;
  request.scenes = {"builtin:tessphere"};
  request.renderers = {"softraster", "raytrace"};
  request.budget_seconds = 30;
  request.bootstrap_replicates = 200;
  StudyHooks hooks;
  hooks.now = [&] { return clock; };
  hooks.prepare = [&](const Family&, size_t n,
                      int width) -> Expected<std::unique_ptr<FrameSource>> {
    return std::unique_ptr<FrameSource>(new SimulatedFrames(double(n), width, clock, rng));
  };
  Expected<StudyResult> r = run_study(request, hooks);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_LE(r->elapsed_seconds, request.budget_seconds * 1.1);
  size_t base = log_spaced(100, 1000000, 13).size();
  size_t full_width = 0, narrower = 0;
  for (const Measurement& m : r->points) (m.width == request.width ? full_width : narrower)++;
  EXPECT_GT(full_width, 2 * base) << "no points added near the crossover";
  // Three N at four narrower widths, two renderers.
  EXPECT_EQ(narrower, 3u * 4u * 2u);
  std::vector<Crossover> along_n, along_pixels;
  for (const Crossover& c : r->crossovers)
    (c.axis == kPixelsAxis ? along_pixels : along_n).push_back(c);
  ASSERT_EQ(along_n.size(), 1u);
  EXPECT_FALSE(along_pixels.empty());
  EXPECT_LT(std::fabs(std::log10(along_n[0].value / true_crossing())), 0.1);
  // Along the pixel count, where the tracer's P·log2 N reaches the z-buffer's cost at that N.
  for (const Crossover& c : along_pixels) {
    double truth = (kZCurve(0, c.n) - 1e-3) / (0.5e-9 * std::log2(c.n));
    EXPECT_LT(std::fabs(std::log10(c.value / truth)), 0.1) << "N = " << c.n;
    EXPECT_TRUE(c.a_faster_below == false) << "the tracer wins with few pixels";
  }
  for (const Measurement& m : r->points) EXPECT_EQ(m.seconds.size(), 5u);
  EXPECT_NE(study_json(*r).find("\"format\": \"rvr-study/1\""), std::string::npos);
}

TEST(StudyRun, RefusesBadInputBeforeAnyWork) {
  bool prepared = false;
  StudyHooks hooks;
  hooks.prepare = [&](const Family&, size_t, int) -> Expected<std::unique_ptr<FrameSource>> {
    prepared = true;
    return internal_error("not reached");
  };
  auto refused = [&](StudyRequest r, const std::string& words) {
    Expected<StudyResult> out = run_study(r, hooks);
    ASSERT_FALSE(out.ok());
    EXPECT_EQ(out.error().kind, ErrorKind::BadInput);
    EXPECT_NE(out.error().message.find(words), std::string::npos) << out.error().message;
  };
  StudyRequest ok;
  ok.scenes = {"builtin:tessphere"};
  ok.renderers = {"softraster", "raytrace"};
  StudyRequest r = ok;
  r.scenes = {"builtin:cornell"};
  refused(r, "builtin:cornell: not a scene family");
  r = ok;
  r.budget_seconds = 0;
  refused(r, "--budget");
  r = ok;
  r.budget_seconds = -5;
  refused(r, "--budget");
  r = ok;
  r.renderers = {"softraster", "nosuch"};
  refused(r, "nosuch");
  EXPECT_FALSE(prepared);
}

TEST(StudyMarkdown, NumbersInPowersOfTen) {
  EXPECT_EQ(format_number(2.1e6), "2.1×10^6");
  EXPECT_EQ(format_number(123.456), "123");
  EXPECT_EQ(format_number(9.97e5), "1.0×10^6");
  EXPECT_EQ(format_number(1000), "1000");
  EXPECT_EQ(format_number(0.5), "0.5");
}

namespace {

// A concluded study of softraster and raytrace on two scenes: "synthetic", where the curves
// cross inside the swept range, and one whose name, like the command, a note and the CPU, holds
// markup that study.html must escape.
const std::string kMarkup = "<script>alert('x')</script>";

StudyResult html_study() {
  Rng rng(5);
  StudyResult r;
  r.scenes = {"synthetic", "odd" + kMarkup};
  r.renderers = {"softraster", "raytrace"};
  r.width = 1024;
  r.height = 768;
  r.mode = "local";
  for (const std::string& scene : r.scenes) {
    r.axes[scene] = "triangles";
    for (const auto& [name, cost] : {std::pair{"softraster", kZCurve}, {"raytrace", kTCurve}})
      for (Measurement m : sweep(name, cost, {kP}, 5, 0.03, rng)) {
        m.scene = scene;
        m.width = r.width;
        m.height = r.height;
        r.points.push_back(m);
      }
  }
  conclude(r, {200, 1});
  r.command = "rvr study " + kMarkup;
  r.notes = {"a note " + kMarkup};
  r.machine.cpu = kMarkup;
  return r;
}

size_t occurrences(const std::string& text, const std::string& what) {
  size_t k = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++k;
  return k;
}

// The SVG of each chart, in page order.
std::vector<std::string> charts_of(const std::string& html) {
  std::vector<std::string> out;
  for (size_t at = html.find("<svg class=\"study-chart\""); at != std::string::npos;
       at = html.find("<svg class=\"study-chart\"", at + 1))
    out.push_back(html.substr(at, html.find("</svg>", at) - at));
  return out;
}

// The point marks of one renderer's series in a chart.
size_t marks_of(const std::string& chart, const std::string& renderer) {
  size_t from = chart.find("<g class=\"series\" data-renderer=\"" + renderer + "\">");
  if (from == std::string::npos) return 0;
  size_t to = chart.find("<g class=\"series\"", from + 1);
  return occurrences(chart.substr(from, to == std::string::npos ? to : to - from),
                     "<circle class=\"mark\"");
}

// The number in attribute `name` of the first element with class `cls` in `svg`.
double attribute(const std::string& svg, const std::string& cls, const std::string& name) {
  size_t at = svg.find("class=\"" + cls + "\"");
  if (at == std::string::npos) return std::nan("");
  at = svg.find(" " + name + "=\"", at);
  return std::stod(svg.substr(at + name.size() + 3));
}

}  // namespace

TEST(StudyHtml, OneChartPerSceneWithEveryRenderersPointsAndModel) {
  StudyResult r = html_study();
  std::string html = study_html(r);
  std::vector<std::string> charts = charts_of(html);
  ASSERT_EQ(charts.size(), r.scenes.size()) << "one pixel count: one chart per scene";
  const size_t per_scene = log_spaced(100, 1000000, 13).size();
  for (const std::string& chart : charts)
    for (const std::string& name : r.renderers) {
      EXPECT_EQ(marks_of(chart, name), per_scene) << name;
      EXPECT_EQ(occurrences(chart, "class=\"model fits\" data-renderer=\"" + name + "\""), 1u)
          << name;
    }
  EXPECT_NE(html.find("×10<sup>"), std::string::npos) << "powers of ten raised";
}

// The measured crossover's line lies within its shaded interval; an open end shades to the
// chart's edge.
TEST(StudyHtml, MarksTheCrossoverWithItsInterval) {
  StudyResult r = html_study();
  ASSERT_FALSE(r.crossovers.empty());
  std::string chart = charts_of(study_html(r))[0];
  ASSERT_EQ(occurrences(chart, "<rect class=\"ci-band\""), 1u);
  double x = attribute(chart, "ci-band", "x"), width = attribute(chart, "ci-band", "width");
  double line = attribute(chart, "crossover-line", "x1");
  EXPECT_GT(width, 1.0);
  EXPECT_LE(x, line);
  EXPECT_GE(x + width, line);

  r.crossovers[0].ci95.high = std::numeric_limits<double>::infinity();
  std::string open = charts_of(study_html(r))[0];
  double plot_right = attribute(open, "plot", "x") + attribute(open, "plot", "width");
  EXPECT_DOUBLE_EQ(attribute(open, "ci-band", "x") + attribute(open, "ci-band", "width"),
                   plot_right);
}

TEST(StudyHtml, EscapesEveryStringFromTheData) {
  std::string html = study_html(html_study());
  EXPECT_EQ(html.find("<script"), std::string::npos) << "markup from the data got through";
  EXPECT_EQ(html.find("alert('x')"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt;"), std::string::npos);
}

// A scene measured at a second pixel count gets, for each N measured at both, a chart of time
// against pixels with each renderer's two points and its model.
TEST(StudyHtml, ChartsAgainstPixelsWhereASceneWasMeasuredAtSeveral) {
  StudyResult r = html_study();
  const size_t points = r.points.size();
  for (size_t i = 0; i < points; ++i)
    if (r.points[i].scene == "synthetic") {
      Measurement m = r.points[i];
      m.pixels = kP / 4;
      for (double& s : m.seconds) s /= 2;
      r.points.push_back(m);
    }
  std::vector<std::string> charts = charts_of(study_html(r));
  const size_t per_scene = log_spaced(100, 1000000, 13).size();
  ASSERT_EQ(charts.size(), r.scenes.size() + per_scene);
  for (const std::string& name : r.renderers) {
    EXPECT_EQ(marks_of(charts[0], name), per_scene) << "the main chart: one pixel count";
    EXPECT_EQ(marks_of(charts[1], name), 2u) << "against pixels: one point at each";
    EXPECT_EQ(occurrences(charts[1], "data-renderer=\"" + name + "\" d=\""), 1u) << name;
  }
}
