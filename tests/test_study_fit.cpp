// The study's cost models: known coefficients recovered within their intervals from synthetic
// measurements with known noise, the intervals' coverage over seeded replicates, and the
// extensions taken only where the data demand them.
#include <gtest/gtest.h>
#include <stddef.h>
#include <stdint.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "rvr/shared/expected.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/fit.h"
#include "rvr/study/least_squares.h"
#include "rvr/study/measurement.h"
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
    for (int s = 0; s < 3; ++s) {
      study::Run run;
      run.session = s;
      run.seconds.assign(5, (2e-3 + 40e-9 * double(n)) * wobble);
      m.runs.push_back(run);
    }
    points.push_back(m);
  }
  ModelFit f = fit_model(ModelForm::ZBuffer, points, {200, 1});
  for (const Coefficient& c : f.coefficients) {
    if (!c.identifiable) continue;
    EXPECT_EQ(c.ci95.low, c.value) << c.name;
    EXPECT_EQ(c.ci95.high, c.value) << c.name;
  }
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
