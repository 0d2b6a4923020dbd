// The study's cost models: non-negative least squares against closed forms, known coefficients
// recovered within their intervals from synthetic measurements with known noise, the intervals'
// coverage over seeded replicates with noise in frames, sessions or points, intervals as wide as
// a model's misfit, the extensions taken only where the data demand them; the models from
// counted work and the counts' exact scaling.
#include <gtest/gtest.h>
#include <stddef.h>
#include <stdint.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/counted_work.h"
#include "rvr/study/fit.h"
#include "rvr/study/least_squares.h"
#include "rvr/study/measurement.h"
#include "rvr/study/study.h"
#include "rvr/study/study_json.h"
#include "rvr/study/study_markdown.h"
#include "rvr/study/sweep_plan.h"
#include "study_synthetic.h"

using namespace rvr;
using namespace rvr::study;
using namespace rvr::study::fake;

namespace {

CostFn model_cost(CostModel model, const std::vector<double>& c) {
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

// Fitting a line to falling values: unconstrained, the slope is −1; held non-negative it is 0
// and the intercept is the weighted mean of y (the least-squares constant), Σ w·y / Σ w. And an
// intercept held at 0: the slope through the origin, Σ x·y / Σ x².
TEST(StudyLeastSquares, NonNegativeMeetsTheClosedFormWhereAConstraintIsActive) {
  const std::vector<std::vector<double>> x = {{1, 0}, {1, 1}, {1, 2}, {1, 3}};
  const std::vector<double> y = {3, 2, 1, 0}, w = {1, 2, 3, 4};
  Expected<std::vector<double>> free = weighted_least_squares(x, y, w, {true, true});
  ASSERT_TRUE(free.ok());
  EXPECT_NEAR((*free)[1], -1.0, 1e-12) << "the data do ask for a negative slope";
  Expected<std::vector<double>> held = nonnegative_least_squares(x, y, w, {true, true});
  ASSERT_TRUE(held.ok());
  EXPECT_EQ((*held)[1], 0.0);
  EXPECT_NEAR((*held)[0], (1 * 3 + 2 * 2 + 3 * 1 + 4 * 0) / 10.0, 1e-12);

  const std::vector<std::vector<double>> through = {{1, 1}, {1, 2}, {1, 3}};
  Expected<std::vector<double>> origin =
      nonnegative_least_squares(through, {1, 3, 5}, {1, 1, 1}, {true, true});
  ASSERT_TRUE(origin.ok());
  EXPECT_EQ((*origin)[0], 0.0);
  EXPECT_NEAR((*origin)[1], (1 * 1 + 2 * 3 + 3 * 5) / 14.0, 1e-12);
  // Dependent columns are refused as by the unconstrained fit.
  EXPECT_FALSE(
      nonnegative_least_squares({{1, 2}, {1, 2}, {1, 2}}, {1, 2, 3}, {1, 1, 1}, {true, true}).ok());
}

// Where the unconstrained minimum is non-negative it is the answer: the two agree.
TEST(StudyLeastSquares, NonNegativeIsTheUnconstrainedFitWhereNoConstraintIsActive) {
  Rng rng(41);
  std::vector<std::vector<double>> x;
  std::vector<double> y, w;
  for (int i = 0; i < 30; ++i) {
    const double p = std::pow(10.0, 3 + 3 * rng.uniform()),
                 n = std::pow(10.0, 2 + 4 * rng.uniform());
    x.push_back({1, p, n, std::sqrt(p * n)});
    const double t = 1e-3 + 8e-9 * p + 40e-9 * n + 3e-9 * std::sqrt(p * n);
    y.push_back(t * (1 + 0.002 * rng.normal()));
    w.push_back(1 / (t * t));
  }
  Expected<std::vector<double>> a = weighted_least_squares(x, y, w, {true, true, true, true}),
                                b = nonnegative_least_squares(x, y, w, {true, true, true, true});
  ASSERT_TRUE(a.ok() && b.ok());
  for (size_t j = 0; j < 4; ++j) {
    ASSERT_GT((*a)[j], 0.0);
    EXPECT_NEAR((*b)[j], (*a)[j], 1e-9 * std::fabs((*a)[j])) << j;
  }
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
// a holds a + b·P. Over 20 seeded studies, each interval holds its truth in at least 17.
TEST(StudyFit, OneImageSizeFoldsThePixelTermIntoTheConstant) {
  int a_covered = 0, c_covered = 0;
  for (int i = 0; i < 20; ++i) {
    Rng rng(11 + i);
    std::vector<Measurement> points =
        sweep("r", model_cost(ModelForm::ZBuffer, kZBuffer), {kP}, 5, 0.02, rng);
    ModelFit f = fit_model(ModelForm::ZBuffer, points, {500, uint64_t(1 + i)});
    ASSERT_TRUE(f.fits) << f.verdict;
    EXPECT_FALSE(f.coefficients[kPixelCoefficient].identifiable);
    EXPECT_EQ(f.fixed_pixels, kP);
    a_covered += covers(f.coefficients[0], kZBuffer[0] + kZBuffer[1] * kP);
    c_covered += covers(f.coefficients[2], kZBuffer[2]);
  }
  EXPECT_GE(a_covered, 17);
  EXPECT_GE(c_covered, 17);
}

// 200 seeded studies for each kind of noise: in every frame alone, in sessions (each run of a
// point its own offset), in points (a scene size that suits the renderer, the same in every
// run: only the scatter between points shows it). The 95% intervals of the per-triangle and
// per-ray-and-level terms hold the true value in 90-98% of them in each case.
TEST(StudyFit, IntervalCoverageOverSeededReplicates) {
  struct Case {
    const char* name;
    Noise noise;
  };
  for (const Case& c : {Case{"frames", {0.05, 0, 0, 0}}, Case{"sessions", {0.03, 0, 0.05, 0}},
                        Case{"points", {0.03, 0, 0, 0.05}}})
    for (auto [form, truth] :
         {std::pair{ModelForm::ZBuffer, kZBuffer}, std::pair{ModelForm::Tracer, kTracer}}) {
      int covered = 0;
      const int replicates = 200;
      for (int i = 0; i < replicates; ++i) {
        Rng rng(1000 + i);
        std::vector<Measurement> points;
        for (size_t n : log_spaced(100, 1000000, 13))
          points.push_back(synthetic_point({"r"}, {model_cost(form, truth)}, kP, double(n), 3, 5,
                                           c.noise, rng)[0]);
        ModelFit f = fit_model(form, points, {400, uint64_t(5000 + i)});
        covered += covers(f.coefficients[2], truth[2]);
      }
      double coverage = double(covered) / replicates;
      EXPECT_GE(coverage, 0.90) << to_string(form) << ", noise in " << c.name;
      EXPECT_LE(coverage, 0.98) << to_string(form) << ", noise in " << c.name;
    }
}

// A model that misses its points has intervals as wide as the misfit, even when every
// repetition is the same (no timing noise at all): points alternately 10% above and below a
// line. The fit is the weighted least-squares line; the scatter about it, s² = Σ e² / (9 − 2)
// with e the relative residuals, is reported as the misfit; and each replicate's c is ĉ plus a
// normal draw of variance (w·s)²·[(XᵀWX)⁻¹]_cc (W = 1/t², w = t₇(0.975) / z(0.975) =
// 2.364624 / 1.959964), so the interval is 2·1.96·w·s·√[(XᵀWX)⁻¹]_cc wide.
TEST(StudyBootstrap, IdenticalRepetitionsAndAMisfitGiveIntervalsTheWidthOfTheMisfit) {
  std::vector<Measurement> points;
  for (size_t n : log_spaced(100, 1000000, 9)) {
    Measurement m;
    m.renderer = "r";
    m.n = double(n);
    m.pixels = kP;
    double wobble = (points.size() % 2 ? 1.1 : 0.9);
    for (int s = 0; s < 3; ++s) {
      study::Run run;
      run.session = s;
      run.seconds.assign(5, (2e-3 + 40e-9 * double(n)) * wobble);
      m.runs.push_back(run);
    }
    points.push_back(m);
  }
  ModelFit f = fit_model(ModelForm::ZBuffer, points, {4000, 1});
  // The closed form: the 2×2 weighted normal equations of t = a' + c·N.
  double s0 = 0, s1 = 0, s2 = 0, t0 = 0, t1 = 0;
  for (const Measurement& m : points) {
    const double t = typical_seconds(m), w = 1 / (t * t);
    s0 += w, s1 += w * m.n, s2 += w * m.n * m.n, t0 += w * t, t1 += w * m.n * t;
  }
  const double det = s0 * s2 - s1 * s1;
  const double a = (s2 * t0 - s1 * t1) / det, c = (s0 * t1 - s1 * t0) / det;
  double rss = 0;
  for (const Measurement& m : points) {
    const double t = typical_seconds(m), e = (t - a - c * m.n) / t;
    rss += e * e;
  }
  const double s = std::sqrt(rss / 7), widen = 2.364624 / 1.959964;
  EXPECT_NEAR(f.coefficients[0].value, a, 1e-9 * a);
  EXPECT_NEAR(f.coefficients[2].value, c, 1e-9 * c);
  EXPECT_EQ(f.repetition_noise, 0.0);
  EXPECT_NEAR(f.misfit, s, 1e-9 * s);
  const double width = 2 * 1.959964 * widen * s * std::sqrt(s0 / det);
  const double measured = f.coefficients[2].ci95.high - f.coefficients[2].ci95.low;
  EXPECT_NEAR(measured, width, 0.05 * width);
  EXPECT_LT(f.coefficients[2].ci95.low, c);
  EXPECT_GT(f.coefficients[2].ci95.high, c);
  ASSERT_EQ(f.replicates.size(), 4000u) << "every replicate is kept for predict_ratio";
}

// The case: a renderer whose frames get slightly faster as N grows over one image size.
// Unconstrained, the fit says each triangle saves time; the study's fit holds the per-triangle
// cost at 0, its interval and every replicate too.
TEST(StudyFit, ANegativeUnitCostIsHeldAtZero) {
  CostFn falling = [](double, double n) { return 5e-3 * (1.0 - 0.02 * std::log10(n) / 6); };
  Rng rng(43);
  std::vector<Measurement> points = sweep("r", falling, {kP}, 5, 0.002, rng);
  std::vector<double> times, w;
  for (const Measurement& m : points) times.push_back(typical_seconds(m));
  for (double t : times) w.push_back(1 / (t * t));
  const std::vector<bool> use = identifiable_terms(ModelForm::ZBuffer, points);
  Expected<std::vector<double>> free =
      weighted_least_squares(design_rows(ModelForm::ZBuffer, points), times, w, use);
  ASSERT_TRUE(free.ok());
  ASSERT_LT((*free)[2], 0.0) << "the planted data ask for a negative cost per triangle";
  ModelFit f = fit_model(ModelForm::ZBuffer, points, {500, 1});
  EXPECT_EQ(f.coefficients[2].value, 0.0);
  for (const Coefficient& c : f.coefficients) {
    if (!c.identifiable) continue;
    EXPECT_GE(c.value, 0.0) << c.name;
    EXPECT_GE(c.ci95.low, 0.0) << c.name;
  }
  for (const std::vector<double>& r : f.replicates)
    for (double v : r) EXPECT_GE(v, 0.0);
  // The same data fitted from counts, the triangles submitted one of them: held at 0 as well.
  for (Measurement& m : points) m.counters["triangles.submitted"] = m.n;
  WorkModel work = fit_work_model("r", ModelForm::ZBuffer, points, {200, 1});
  ASSERT_EQ(work.terms.size(), 2u);
  EXPECT_EQ(work.terms[1].name, "triangles.submitted");
  EXPECT_EQ(work.terms[1].value, 0.0);
}

// Each replicate keeps every point, in order, its time drawn from its own runs and rounds.
TEST(StudyBootstrap, ReplicatesResampleEachPointsOwnRepetitions) {
  std::vector<Measurement> points(6);
  for (size_t i = 0; i < points.size(); ++i)
    for (int s = 0; s < 3; ++s) {
      study::Run run;
      run.session = s;
      for (int k = 0; k < 5; ++k) run.seconds.push_back(1.0 + double(i) + 0.1 * k);
      points[i].runs.push_back(run);
    }
  Rng rng(3);
  for (int r = 0; r < 50; ++r) {
    std::vector<double> m = resample_times(points, rng);
    ASSERT_EQ(m.size(), points.size());
    for (size_t i = 0; i < m.size(); ++i) {
      EXPECT_GE(m[i], 1.0 + double(i));
      EXPECT_LE(m[i], 1.0 + double(i) + 0.4);
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

// Along depth complexity D (occluders), a z-buffer shades and tests P·D fragments: the textbook
// form there has d·P·D, recovered within its interval from data that have it.
TEST(StudyModelChoice, DepthComplexityAddsTheFragmentTerm) {
  const std::vector<double> truth = {1e-3, 8e-9, 20e-6, 3e-9};  // a, b, c, d
  CostFn cost = [&](double p, double d) {
    return truth[0] + truth[1] * p + truth[2] * d + truth[3] * p * d;
  };
  Rng rng(29);
  std::vector<Measurement> points;
  for (double p : {256.0 * 192, 512.0 * 384, kP})
    for (size_t d : log_spaced(1, 256, 9))
      points.push_back(synthetic("r", cost, p, double(d), 5, 0.03, rng));
  CostModel textbook(ModelForm::ZBuffer);
  textbook.depth = true;
  ModelFit f = fit_chosen_model(textbook, points, {1000, 1});
  ASSERT_TRUE(f.fits) << f.verdict;
  EXPECT_NE(f.formula.find("d·P·D"), std::string::npos) << f.formula;
  ASSERT_EQ(f.coefficients.size(), 4u) << f.formula;
  EXPECT_EQ(f.coefficients[3].name, "d");
  for (size_t j = 0; j < truth.size(); ++j)
    EXPECT_TRUE(covers(f.coefficients[j], truth[j]))
        << f.coefficients[j].name << " = " << truth[j] << " not in [" << f.coefficients[j].ci95.low
        << ", " << f.coefficients[j].ci95.high << "]";
}

// A z-buffer whose triangles cost 400 ns each up to N = 10^4 and 20 ns past it (each costs its
// area until triangles are smaller than a block, then its setup only). With a steeper-only knee
// that is a negative f; the study takes the flatter knee, f·min(N, k), with c and f both
// non-negative. Over 10 seeded studies: the flatter knee at 10^4 in every one, each coefficient
// within its interval in at least 8.
TEST(StudyModelChoice, AFlatterSlopePastAKneeIsFoundWithNonNegativeCosts) {
  const double knee = double(log_spaced(100, 1000000, 13)[6]);
  ASSERT_EQ(knee, 1e4);
  const std::vector<double> truth = {1e-3, 8e-9, 20e-9, 380e-9};  // a, b, c, f
  CostFn cost = [&](double p, double n) {
    return truth[0] + truth[1] * p + truth[2] * n + truth[3] * std::min(n, knee);
  };
  std::vector<int> covered(truth.size(), 0);
  for (int i = 0; i < 10; ++i) {
    Rng rng(47 + i);
    std::vector<Measurement> points = sweep("r", cost, {256.0 * 192, kP}, 5, 0.03, rng);
    if (i == 0) {
      CostModel steeper(ModelForm::ZBuffer, false, knee, false);
      std::vector<double> times, w;
      for (const Measurement& m : points) times.push_back(typical_seconds(m));
      for (double t : times) w.push_back(1 / (t * t));
      Expected<std::vector<double>> free = weighted_least_squares(
          design_rows(steeper, points), times, w, identifiable_terms(steeper, points));
      ASSERT_TRUE(free.ok());
      EXPECT_LT((*free)[3], 0.0) << "as a steeper knee, the data need a negative f";
    }
    ModelFit f = fit_chosen_model(ModelForm::ZBuffer, points, {500, uint64_t(1 + i)});
    ASSERT_TRUE(f.fits) << f.verdict;
    EXPECT_EQ(f.model.knee, knee) << f.formula;
    EXPECT_TRUE(f.model.flatter) << f.formula;
    EXPECT_FALSE(f.model.edges) << f.formula;
    EXPECT_NE(f.formula.find("f·min(N, 1.0×10^4)"), std::string::npos) << f.formula;
    ASSERT_EQ(f.coefficients.size(), truth.size());
    for (size_t j = 0; j < truth.size(); ++j) {
      EXPECT_GE(f.coefficients[j].ci95.low, 0.0) << f.coefficients[j].name;
      covered[j] += covers(f.coefficients[j], truth[j]);
    }
  }
  for (size_t j = 0; j < truth.size(); ++j) EXPECT_GE(covered[j], 8) << j;
}

namespace {

// Counts like a z-buffer's: every triangle submitted; fewer set up as they shrink; fragments
// from the covered area and the triangles' edges; the covered pixels a fixed share of the frame
// (they follow the pixel count); nothing clipped; one shadow cube map whatever the frame.
std::map<std::string, double> zbuffer_counts(double p, double n) {
  return {{"triangles.submitted", n},
          {"triangles.setup", n / (1 + n / 2e4)},
          {"fragments.generated", 0.35 * p + 0.5 * std::sqrt(p * n)},
          {"pixels.covered", 0.35 * p},
          {"triangles.clipped", 0},
          {"shadows.triangles_setup", 12}};
}

const std::map<std::string, double> kUnitCosts = {{"pixels", 8e-9},
                                                  {"triangles.submitted", 20e-9},
                                                  {"triangles.setup", 60e-9},
                                                  {"fragments.generated", 5e-9}};
constexpr double kFrameCost = 0.2e-3;
const std::vector<double> kThreeSizes = {256.0 * 192, 512.0 * 384, kP};

}  // namespace

// Which counts enter a work model: absent ones are not mentioned, one zero or the same at every
// point is left out (the constant holds it), one that follows the counts before it too.
TEST(StudyWork, CountsAbsentConstantOrFollowingAreLeftOutAndSaySo) {
  Rng rng(53);
  Noise noise;
  noise.frame = 0.03;
  WorkModel m = fit_work_model(
      "softraster", ModelForm::ZBuffer,
      counted_sweep("softraster", zbuffer_counts, kFrameCost, kUnitCosts, kThreeSizes, noise, rng),
      {200, 1});
  std::vector<std::string> terms;
  for (const Coefficient& c : m.terms) terms.push_back(c.name);
  EXPECT_EQ(terms, (std::vector<std::string>{"frame", "pixels", "triangles.submitted",
                                             "triangles.setup", "fragments.generated"}));
  ASSERT_EQ(m.counts.size(), terms.size());
  for (const std::string& what : m.counts) EXPECT_FALSE(what.empty());
  std::map<std::string, std::string> why;
  for (const LeftOutCounter& l : m.left_out) why[l.counter] = l.why;
  EXPECT_EQ(why.size(), 3u);
  EXPECT_EQ(why["triangles.clipped"], "zero at every point");
  EXPECT_NE(why["shadows.triangles_setup"].find("12 at every point"), std::string::npos);
  EXPECT_NE(why["pixels.covered"].find("follows pixels"), std::string::npos)
      << why["pixels.covered"];
  EXPECT_FALSE(why.count("hiz.blocks_rejected")) << "a count the renderer does not make";
  // A count non-zero at two points only cannot be told from the frame by leaving one out.
  std::vector<Measurement> points =
      counted_sweep("softraster", zbuffer_counts, kFrameCost, kUnitCosts, kThreeSizes, noise, rng);
  points[3].counters["triangles.clipped"] = 5;
  points[20].counters["triangles.clipped"] = 9;
  WorkModel rare = fit_work_model("softraster", ModelForm::ZBuffer, points, {100, 1});
  auto clipped =
      std::find_if(rare.left_out.begin(), rare.left_out.end(),
                   [](const LeftOutCounter& l) { return l.counter == "triangles.clipped"; });
  ASSERT_NE(clipped, rare.left_out.end());
  EXPECT_EQ(clipped->why, "non-zero at 2 of 39 points: too few to tell its cost");
}

// Frames that cost exactly u0 + Σ u·count (with noise in frames, sessions and points): the work
// model recovers every unit cost within its interval in 88-99% of 100 seeded studies.
TEST(StudyWork, RecoversKnownUnitCostsWithinTheirIntervals) {
  std::vector<double> truth = {kFrameCost};
  for (const char* name :
       {"pixels", "triangles.submitted", "triangles.setup", "fragments.generated"})
    truth.push_back(kUnitCosts.at(name));
  std::vector<int> covered(truth.size(), 0);
  const int seeds = 100;
  for (int i = 0; i < seeds; ++i) {
    Rng rng(600 + i);
    const Noise noise{0.03, 0.0, 0.02, 0.02};
    WorkModel m = fit_work_model("softraster", ModelForm::ZBuffer,
                                 counted_sweep("softraster", zbuffer_counts, kFrameCost, kUnitCosts,
                                               kThreeSizes, noise, rng),
                                 {200, uint64_t(700 + i)});
    ASSERT_EQ(m.terms.size(), truth.size());
    ASSERT_TRUE(m.fits) << m.verdict;
    ASSERT_EQ(m.replicates.size(), 200u);
    for (size_t j = 0; j < truth.size(); ++j) {
      EXPECT_GE(m.terms[j].ci95.low, 0.0);
      covered[j] += covers(m.terms[j], truth[j]);
    }
  }
  for (size_t j = 0; j < truth.size(); ++j) {
    EXPECT_GE(covered[j], 88) << j;
    EXPECT_LE(covered[j], 99) << j;
  }
}

namespace {

// One point of a renderer at (pixels, n) with the given counts and a nominal time.
Measurement counted_point(const std::string& renderer, const std::string& scene, double pixels,
                          double n, std::map<std::string, double> counters, Rng& rng) {
  Measurement m = synthetic(
      renderer, [](double, double) { return 1e-3; }, pixels, n, 5, 0.01, rng);
  m.scene = scene;
  m.counters = std::move(counters);
  return m;
}

}  // namespace

// The chapter's claims on counts, exact: nodes per ray = α + β·log2 N gives back β and α to
// rounding and R² 1; fragments per pixel = 1 + 0.75·D along depth, likewise; triangles set up in
// proportion to N: log-log slope 1. And each count's log-log slope against N and P: a count
// ∝ N^0.5·P gives 0.5 and 1.
TEST(StudyCounts, ClaimsAndScalingAreRecoveredExactly) {
  const double alpha = 1.25, beta = 2.5;
  Rng rng(59);
  std::vector<Measurement> traced, drawn, deep;
  for (size_t n : log_spaced(100, 1000000, 13)) {
    const double rays = kP + 0.5 * kP;  // primary and shadow
    traced.push_back(
        counted_point("raytrace", "tessphere", kP, double(n),
                      {{"rays.primary", kP},
                       {"rays.shadow", 0.5 * kP},
                       {"bvh.nodes_visited", rays * (alpha + beta * std::log2(double(n)))},
                       {"primitive_tests", 3 * std::sqrt(double(n)) * kP}},
                      rng));
    drawn.push_back(counted_point(
        "softraster", "tessphere", kP, double(n),
        {{"triangles.submitted", double(n)}, {"triangles.setup", 0.3 * double(n)}}, rng));
  }
  for (double p : {256.0 * 192, 512.0 * 384})
    traced.push_back(
        counted_point("raytrace", "tessphere", p, 1000,
                      {{"rays.primary", p},
                       {"rays.shadow", 0.5 * p},
                       {"bvh.nodes_visited", 1.5 * p * (alpha + beta * std::log2(1000))},
                       {"primitive_tests", 3 * std::sqrt(1000.0) * p}},
                      rng));
  for (size_t d : log_spaced(1, 256, 9))
    deep.push_back(counted_point("softraster", "occluders", kP, double(d),
                                 {{"triangles.submitted", 2.0 * double(d)},
                                  {"fragments.generated", kP * (1 + 0.75 * double(d))}},
                                 rng));

  std::vector<CountClaim> claims =
      count_claims("raytrace", ModelForm::Tracer, "tessphere", "triangles", kP, traced);
  ASSERT_EQ(claims.size(), 1u);
  EXPECT_EQ(claims[0].claim, "nodes_per_ray");
  EXPECT_EQ(claims[0].against, "log2 N");
  EXPECT_NEAR(claims[0].slope, beta, 1e-9 * beta);
  EXPECT_NEAR(claims[0].intercept, alpha, 1e-9 * beta);
  EXPECT_NEAR(claims[0].r2, 1.0, 1e-12);
  EXPECT_EQ(claims[0].points, 13u);

  claims = count_claims("softraster", ModelForm::ZBuffer, "occluders", "depth", kP, deep);
  ASSERT_EQ(claims.size(), 1u);
  EXPECT_EQ(claims[0].claim, "fragments_per_pixel");
  EXPECT_NEAR(claims[0].slope, 0.75, 1e-12);
  EXPECT_NEAR(claims[0].intercept, 1.0, 1e-9);

  claims = count_claims("softraster", ModelForm::ZBuffer, "tessphere", "triangles", kP, drawn);
  ASSERT_EQ(claims.size(), 1u);
  EXPECT_EQ(claims[0].claim, "triangles_set_up");
  EXPECT_EQ(claims[0].quantity, "triangles.setup");
  EXPECT_NEAR(claims[0].exponent, 1.0, 1e-12);
  EXPECT_NEAR(claims[0].slope, 0.3, 1e-12);
  EXPECT_TRUE(
      count_claims("softraster", ModelForm::ZBuffer, "tessphere", "depth", kP, drawn).empty())
      << "fragments per pixel are checked along depth only, and need the fragment count";

  std::map<std::pair<std::string, std::string>, double> slope;
  for (const CountScaling& s :
       count_scaling("raytrace", ModelForm::Tracer, "tessphere", "triangles", kP, traced))
    slope[{s.counter, s.axis}] = s.exponent;
  EXPECT_NEAR((slope[{"primitive_tests", "triangles"}]), 0.5, 1e-12);
  EXPECT_NEAR((slope[{"primitive_tests", "pixels"}]), 1.0, 1e-12);
  EXPECT_NEAR((slope[{"rays.primary", "triangles"}]), 0.0, 1e-12);
  EXPECT_NEAR((slope[{"rays.primary", "pixels"}]), 1.0, 1e-12);
  EXPECT_FALSE(slope.count({"rays.reflection", "triangles"})) << "a count never made";
}

// The counted work goes into study.json, study.md and study.html, and a study read back is
// concluded to the same work models. A study without counts has no such section.
TEST(StudyWork, WrittenToEveryOutputAndConcludedAgainTheSame) {
  StudyResult r;
  r.scenes = {"tessphere"};
  r.axes["tessphere"] = "triangles";
  r.renderers = {"softraster"};
  r.width = 1024;
  r.height = 768;
  r.mode = "local";
  r.budget_seconds = 60;
  r.repetitions = 5;
  r.sessions_per_point = 3;
  r.noise_threshold = 0.03;
  r.seed = 1;
  r.bootstrap_replicates = 100;
  r.run_id = "test";
  for (int s = 0; s < 3; ++s) r.sessions.push_back({"preparation", "test", {}});
  Rng rng(61);
  Noise noise;
  r.points =
      counted_sweep("softraster", zbuffer_counts, kFrameCost, kUnitCosts, kThreeSizes, noise, rng);
  for (Measurement& m : r.points) {
    m.scene = "tessphere";
    m.width = int(std::lround(std::sqrt(m.pixels * 4 / 3)));
    m.height = int(std::lround(m.pixels / m.width));
  }
  StudyResult plain = r;
  conclude(r, {r.bootstrap_replicates, r.seed});
  ASSERT_EQ(r.work_models.size(), 1u);
  EXPECT_FALSE(r.count_scaling.empty());
  EXPECT_EQ(r.count_claims.size(), 1u);
  const std::string json = study_json(r);
  for (const char* key :
       {"\"work_models\"", "\"count_scaling\"", "\"count_claims\"", "\"misfit\"", "\"left_out\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
  const std::string md = study_markdown(r);
  EXPECT_NE(md.find("## Cost models from counted work"), std::string::npos);
  EXPECT_NE(md.find("## The chapter's claims, checked on counts"), std::string::npos);
  EXPECT_NE(md.find("| softraster | triangles.setup |"), std::string::npos);
  Expected<StudyResult> back = read_study_json(json, "study.json");
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_TRUE(back->work_models.empty()) << "computed again, not read";
  conclude(*back, {back->bootstrap_replicates, back->seed});
  ASSERT_EQ(back->work_models.size(), 1u);
  ASSERT_EQ(back->work_models[0].terms.size(), r.work_models[0].terms.size());
  for (size_t j = 0; j < r.work_models[0].terms.size(); ++j) {
    EXPECT_DOUBLE_EQ(back->work_models[0].terms[j].value, r.work_models[0].terms[j].value);
    EXPECT_DOUBLE_EQ(back->work_models[0].terms[j].ci95.low, r.work_models[0].terms[j].ci95.low);
  }
  for (Measurement& m : plain.points) m.counters.clear();
  conclude(plain, {plain.bootstrap_replicates, plain.seed});
  const std::string without = study_markdown(plain);
  EXPECT_EQ(without.find("counted work"), std::string::npos);
  EXPECT_EQ(without.find("checked on counts"), std::string::npos);
}
