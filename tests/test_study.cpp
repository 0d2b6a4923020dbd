// The study's statistics and sweep, tested as the renderers are: synthetic measurements with
// known noise at every level the study resamples (frames, rounds, sessions, points); crossovers
// placed where closed forms put them; over hundreds of seeds, tied renderers that rarely give a
// crossover and a real one that is found; prediction checks that fail on a wrong model; the
// whole sweep within its budget on a simulated clock, quiet or busy.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stddef.h>
#include <stdint.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/glm.hpp>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "loglog_chart.h"
#include "rvr/core/camera.h"
#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/scene_io/scene_loader.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/counted_work.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/grid_of_copies.h"
#include "rvr/study/measurement.h"
#include "rvr/study/memory_estimate.h"
#include "rvr/study/merge.h"
#include "rvr/study/prediction_checks.h"
#include "rvr/study/run_study.h"
#include "rvr/study/scene_changes.h"
#include "rvr/study/study.h"
#include "rvr/study/study_html.h"
#include "rvr/study/study_json.h"
#include "rvr/study/study_markdown.h"
#include "rvr/study/sweep_plan.h"
#include "rvr/study/system_probe.h"
#include "rvr/study/trend.h"
#include "study_synthetic.h"

using namespace rvr;
using namespace rvr::study;
using namespace rvr::study::fake;

namespace {

constexpr double kP = 1024.0 * 768;

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

// 16 N from 10^2 to 10^7, three a decade: the sweep's grid along N.
std::vector<double> grid() {
  std::vector<double> out;
  for (size_t n : log_spaced(100, 10000000, 16)) out.push_back(double(n));
  return out;
}

CompareOptions options(int replicates, uint64_t seed) {
  return CompareOptions{BootstrapOptions{replicates, seed}, 0.03};
}

bool covers(const Interval& i, double truth) {
  return i.low <= truth && truth <= i.high;
}

}  // namespace

// Holm's step-down adjustment: sorted p multiplied by m, m−1, …, kept monotone (a worked
// example: p = 0.01, 0.04, 0.03, 0.005 for four tests).
TEST(StudyCrossover, HolmAdjustsAsTheTextbookSays) {
  std::vector<double> adjusted = holm_adjusted({0.01, 0.04, 0.03, 0.005});
  EXPECT_DOUBLE_EQ(adjusted[3], 0.02);  // 4 × 0.005
  EXPECT_DOUBLE_EQ(adjusted[0], 0.03);  // 3 × 0.01
  EXPECT_DOUBLE_EQ(adjusted[2], 0.06);  // 2 × 0.03
  EXPECT_DOUBLE_EQ(adjusted[1], 0.06);  // max(1 × 0.04, 0.06): never below the one before
  EXPECT_DOUBLE_EQ(holm_adjusted({0.6, 0.7})[0], 1.0);
}

// A straight line through the k nearest points, evaluated at each: exact on a line, the mean
// of the window on a constant, and its residual degrees of freedom n − 2 when the window is
// every point (one least-squares line).
TEST(StudyTrend, IsTheLocalStraightLine) {
  std::vector<double> x = {0, 1, 2, 3, 4, 5, 6, 7};
  std::vector<double> line, bump(8, 0.0);
  for (double v : x) line.push_back(2 - 0.5 * v);
  bump[6] = 5;
  Trend trend(x);
  std::vector<double> t = trend.apply(line);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(t[i], line[i], 1e-12);
  EXPECT_NEAR(trend.residual_variance(line), 0.0, 1e-20);
  // The bump weighs in the trend of its neighbours only.
  std::vector<double> b = trend.apply(bump);
  EXPECT_EQ(b[0], 0.0);
  EXPECT_GT(b[6], 0.0);
  EXPECT_LT(b[6], 5.0);
  Trend global(std::vector<double>{0, 1, 2, 3, 4}, 5);
  EXPECT_NEAR(global.residual_dof(), 3.0, 1e-12);
}

// Two power laws t_a = A·N^α, t_b = B·N^β, sampled a decade apart: log(t_a / t_b) is a straight
// line in log N, so the crossing interpolated in log N is the closed form N* = (B/A)^(1/(α−β))
// exactly. Interpolating in N instead is off by far more than 1%.
TEST(StudyCrossover, TwoSamplesADecadeApartCrossWhereTheClosedFormSays) {
  const double A = 3e-5, alpha = 0.55, B = 2e-3, beta = 0.12;
  const double truth = std::pow(B / A, 1 / (alpha - beta));
  const double n0 = std::pow(10.0, std::floor(std::log10(truth))), n1 = 10 * n0;
  auto d = [&](double n) { return std::log(A * std::pow(n, alpha) / (B * std::pow(n, beta))); };
  const double at = std::exp(zero_crossing({std::log(n0), std::log(n1)}, {d(n0), d(n1)}, 0, 1));
  EXPECT_NEAR(at / truth, 1.0, 0.01) << at << " vs " << truth;
  // The same through compare_curves on a noise-free grid a decade apart.
  std::vector<double> ns;
  for (int e = 1; e <= 8; ++e) ns.push_back(std::pow(10.0, e));
  Noise quiet;
  quiet.frame = 0;
  Rng rng(1);
  auto [a, b] =
      sweep_pair([&](double, double n) { return A * std::pow(n, alpha); },
                 [&](double, double n) { return B * std::pow(n, beta); }, ns, kP, quiet, rng);
  CurveComparison c = compare_curves(a, b, "triangles", options(200, 1));
  ASSERT_EQ(c.crossovers.size(), 1u);
  EXPECT_NEAR(c.crossovers[0].value / truth, 1.0, 0.01);
  EXPECT_TRUE(c.crossovers[0].a_faster_below);
}

TEST(StudyCrossover, PlacedWhereTheMeasuredCurvesCross) {
  Rng rng(21);
  Noise noise;
  noise.frame = 0.03;
  noise.session = 0.02;
  std::vector<double> ns;
  for (size_t n : log_spaced(100, 1000000, 13)) ns.push_back(double(n));
  auto [z, t] = sweep_pair(kZCurve, kTCurve, ns, kP, noise, rng);
  CurveComparison c = compare_curves(z, t, "triangles", options(1000, 2));
  ASSERT_EQ(c.crossovers.size(), 1u);
  const Crossover& x = c.crossovers[0];
  const double truth = true_crossing();
  EXPECT_TRUE(x.measured);
  EXPECT_TRUE(x.a_faster_below);  // the z-buffer wins with few triangles
  EXPECT_LT(std::fabs(std::log10(x.value / truth)), 0.1) << x.value << " vs " << truth;
  EXPECT_TRUE(covers(x.ci95, truth)) << x.ci95.low << " – " << x.ci95.high;
  EXPECT_GE(x.below_points, 2u);
  EXPECT_GE(x.above_points, 2u);
  EXPECT_FALSE(c.dominance.has_value());
}

namespace {

// The noise of the simulation: 1% per frame, 3% per point (a size that suits one
// renderer, in every run), and the shared and per-process noise a real machine adds.
Noise study_noise() {
  Noise n;
  n.frame = 0.01;
  n.point = 0.03;
  n.session = 0.01;
  n.round = 0.02;
  return n;
}

}  // namespace

// 200 studies of two renderers of the same cost: a crossover in at most 5% of them (and a
// dominance, a claim that one is faster, in at most 5% too: Holm holds the family-wise error).
TEST(StudyCrossover, TiedRenderersGiveAFalseCrossoverRarely) {
  const int studies = 200;
  int crossovers = 0, dominance = 0;
  for (int s = 0; s < studies; ++s) {
    Rng rng(7000 + s);
    auto [a, b] = sweep_pair(kZCurve, kZCurve, grid(), kP, study_noise(), rng);
    CurveComparison c = compare_curves(a, b, "triangles", options(300, 9000 + s));
    crossovers += !c.crossovers.empty();
    dominance += c.dominance.has_value();
  }
  EXPECT_LE(crossovers, studies * 5 / 100) << crossovers << " false crossovers in " << studies;
  EXPECT_LE(dominance, studies * 5 / 100) << dominance << " false dominance in " << studies;
  RecordProperty("false_crossovers", crossovers);
  RecordProperty("false_dominance", dominance);
}

// 200 studies of a ratio that changes by 10% a decade, crossing in the middle of the sweep: the
// crossover is found in at least 90% of them, and its interval holds the truth in most.
TEST(StudyCrossover, ARealCrossoverOfTenPercentADecadeIsFound) {
  const double truth = std::sqrt(1e2 * 1e7);
  const CostFn slower_below = [truth](double, double n) {
    return 1e-2 * std::pow(1.1, std::log10(n / truth));
  };
  const CostFn flat = [](double, double) { return 1e-2; };
  const int studies = 200;
  int found = 0, covered = 0, placed = 0;
  for (int s = 0; s < studies; ++s) {
    Rng rng(8000 + s);
    auto [a, b] = sweep_pair(flat, slower_below, grid(), kP, study_noise(), rng);
    CurveComparison c = compare_curves(a, b, "triangles", options(300, 9500 + s));
    if (c.crossovers.size() != 1) continue;
    ++found;
    covered += covers(c.crossovers[0].ci95, truth);
    placed += std::fabs(std::log10(c.crossovers[0].value / truth)) < 0.5;
  }
  EXPECT_GE(found, studies * 90 / 100) << found << " of " << studies << " found";
  EXPECT_GE(placed, found * 90 / 100) << placed << " of " << found << " within half a decade";
  EXPECT_GE(covered, found * 85 / 100) << covered << " of " << found << " intervals hold it";
  RecordProperty("found", found);
  RecordProperty("covered", covered);
}

// One renderer faster by 30% throughout: a dominance at every point, with its smallest lead; a
// point where the other measured faster is listed.
TEST(StudyCrossover, ADominanceSaysWhereItIsSignificant) {
  Rng rng(31);
  const CostFn slower = [](double p, double n) { return 1.3 * kZCurve(p, n); };
  auto [z, t] = sweep_pair(kZCurve, slower, grid(), kP, study_noise(), rng);
  CurveComparison apart = compare_curves(z, t, "triangles", options(500, 2));
  EXPECT_TRUE(apart.crossovers.empty());
  ASSERT_TRUE(apart.dominance.has_value());
  EXPECT_EQ(apart.dominance->faster, "softraster");
  EXPECT_EQ(apart.dominance->significant, grid().size());
  EXPECT_GT(apart.dominance->min_ratio, 1.15);
  EXPECT_TRUE(apart.dominance->contrary.empty());
  // Every run of one point made raytrace faster there: listed as contrary, not significant.
  for (study::Run& run : t[5].runs)
    for (double& s : run.seconds) s /= 1.5;
  CurveComparison one = compare_curves(z, t, "triangles", options(500, 2));
  ASSERT_TRUE(one.dominance.has_value());
  ASSERT_EQ(one.dominance->contrary.size(), 1u);
  EXPECT_EQ(one.dominance->contrary[0], grid()[5]);
}

// Too few points for a trend: nothing concluded, and why.
TEST(StudyCrossover, TooFewPointsConcludeNothing) {
  Rng rng(3);
  auto [a, b] = sweep_pair(kZCurve, kTCurve, {1e2, 1e4, 1e6}, kP, study_noise(), rng);
  CurveComparison c = compare_curves(a, b, "triangles", options(100, 1));
  EXPECT_TRUE(c.crossovers.empty());
  EXPECT_FALSE(c.dominance.has_value());
  EXPECT_FALSE(c.tie);
  EXPECT_NE(c.comparison.inconclusive.find("at least 4"), std::string::npos)
      << c.comparison.inconclusive;
}

// Measured up to 2000 only, raytrace never catches up: softraster wins where significant, and
// the fitted models' crossover is reported as outside the range, not as measured.
TEST(StudyCrossover, OutsideTheSweptRangeIsReportedAsSuch) {
  Rng rng(8);
  StudyResult r;
  r.scenes = {"synthetic"};
  r.renderers = {"softraster", "raytrace"};
  r.axes["synthetic"] = "triangles";
  r.width = 1024;
  r.height = 768;
  r.noise_threshold = 0.03;
  Noise noise;
  noise.frame = 0.02;
  for (size_t n : log_spaced(100, 2000, 7))
    for (Measurement& m : synthetic_point({"softraster", "raytrace"}, {kZCurve, kTCurve}, kP,
                                          double(n), 3, 5, noise, rng))
      r.points.push_back(m);
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
  EXPECT_NE(md.find("where significant"), std::string::npos) << md;
}

namespace {

// A concluded study of softraster and raytrace crossing inside the swept range, with its checks'
// points measured from `z` and `t` (the truth at the check points), then evaluated.
StudyResult checked_study(const CostFn& z, const CostFn& t, uint64_t seed) {
  Rng rng(seed);
  StudyResult r;
  r.scenes = {"synthetic"};
  r.renderers = {"softraster", "raytrace"};
  r.axes["synthetic"] = "triangles";
  r.width = 1024;
  r.height = 768;
  r.noise_threshold = 0.03;
  Noise noise;
  noise.frame = 0.02;
  for (size_t n : log_spaced(100, 1000000, 13))
    for (Measurement& m :
         synthetic_point(r.renderers, {kZCurve, kTCurve}, kP, double(n), 3, 5, noise, rng))
      r.points.push_back(m);
  conclude(r, {300, seed});
  for (const CheckPoint& p : plan_checks(r))
    for (Measurement& m :
         synthetic_point(r.renderers, {z, t}, kP, double(p.scene_n), 3, 5, noise, rng)) {
      m.width = p.width;
      m.height = p.width * 3 / 4;
      r.check_points.push_back(m);
    }
  evaluate_checks(r, options(300, seed));
  return r;
}

}  // namespace

// The checks measure off the grid, a third of and three times the crossover: where the truth
// is the sweep's, they hold.
TEST(StudyChecks, HoldWhereTheConclusionIsTrue) {
  StudyResult r = checked_study(kZCurve, kTCurve, 41);
  ASSERT_EQ(r.crossovers.size(), 1u);
  ASSERT_EQ(r.checks.size(), 2u);
  for (const PredictionCheck& c : r.checks) {
    EXPECT_NEAR(std::fabs(std::log10(c.at / c.crossover)), std::log10(3.0), 0.1);
    bool on_grid = false;
    for (const Measurement& m : r.points) on_grid |= std::fabs(std::log(m.n / c.at)) < 0.05;
    EXPECT_FALSE(on_grid) << "checked at a point of the sweep: " << c.at;
    const bool z_faster = kZCurve(kP, c.at) < kTCurve(kP, c.at);  // the truth at that N
    EXPECT_EQ(c.predicted_faster, z_faster ? "softraster" : "raytrace");
    EXPECT_EQ(c.verdict, "holds") << c.why;
  }
  EXPECT_FALSE(r.crossovers[0].contradicted);
}

// Over 100 seeded studies whose checks measure the truth, a check fails in at most 5% of them:
// a check that fails is evidence, not noise.
TEST(StudyChecks, RarelyFailWhereTheConclusionIsTrue) {
  const int studies = 100;
  int failed = 0, held = 0;
  for (int s = 0; s < studies; ++s) {
    StudyResult r = checked_study(kZCurve, kTCurve, 600 + s);
    bool any = false;
    for (const PredictionCheck& c : r.checks) {
      any = any || c.verdict == "fails";
      held += c.verdict == "holds";
    }
    failed += any;
  }
  EXPECT_LE(failed, studies * 5 / 100)
      << failed << " of " << studies << " studies had a check fail";
  EXPECT_GE(held, studies) << "checks hold at under half the points they measured";
}

// A planted wrong conclusion: at the check points the other renderer is faster (the renderer's
// cost off the grid is not what the sweep saw). The check fails and the crossover is demoted in
// study.md.
TEST(StudyChecks, FailOnAWrongPredictionAndDemoteIt) {
  const CostFn swapped = [](double p, double n) { return kTCurve(p, n); };
  const CostFn swapped_back = [](double p, double n) { return kZCurve(p, n); };
  StudyResult r = checked_study(swapped, swapped_back, 42);
  ASSERT_EQ(r.checks.size(), 2u);
  for (const PredictionCheck& c : r.checks) EXPECT_EQ(c.verdict, "fails") << c.why;
  ASSERT_EQ(r.crossovers.size(), 1u);
  EXPECT_TRUE(r.crossovers[0].contradicted);
  const std::string md = study_markdown(r);
  EXPECT_NE(md.find("not confirmed"), std::string::npos) << md;
  EXPECT_NE(md.find("Fails"), std::string::npos) << md;
}

// A planted wrong model: the renderer measured is on the sweep's side, but its fitted model
// (here: the per-triangle cost tripled) predicts a ratio the checks do not measure.
TEST(StudyChecks, FailOnAWrongModel) {
  Rng rng(43);
  StudyResult r = checked_study(kZCurve, kTCurve, 43);
  ASSERT_FALSE(r.models.empty());
  ModelFit& z = r.models[0].fits.at("synthetic");
  ASSERT_TRUE(z.fits) << z.verdict;
  for (size_t k = 0; k < z.coefficients.size(); ++k)
    if (z.coefficients[k].name == "c") {
      z.coefficients[k].value *= 3;
      for (std::vector<double>& rep : z.replicates) rep[k] *= 3;
    }
  evaluate_checks(r, options(300, 43));
  size_t failed = 0;
  for (const PredictionCheck& c : r.checks) failed += c.verdict == "fails";
  EXPECT_GE(failed, 1u);
}

namespace {

// Frames whose cost comes from kZCurve (renderer 0) and kTCurve (1), on a clock that only they,
// preparing (1 µs a triangle) and the system probe advance. Frames started while the clock is
// in [busy_from, busy_to) take twice as long: something else is running; with `load` every
// frame does, by a factor that varies from round to round (a constant load the probe sees).
constexpr double kNever = std::numeric_limits<double>::infinity();

struct SimulatedMachine {
  double clock = 0;
  Rng rng{1};
  double busy_from = 0, busy_to = 0;
  bool load = false;
  double frame_noise = 0.03;
  // The first frame started at or after stall_at takes stall_seconds more: a step far longer
  // than any before it.
  double stall_at = kNever, stall_seconds = 0;
  // The study's budget clock (Session::stop_steps_when_out_of_time): a step that would end past
  // it ends there with ErrorKind::OutOfTime, as a killed worker's does. Unset, or with
  // `ignore_budget`, steps end when they end.
  std::function<double()> seconds_left;
  bool ignore_budget = false;
  double slowdown() const { return (clock >= busy_from && clock < busy_to) ? 2.0 : 1.0; }
  // Advances the clock by a step of `seconds`, or to the budget's end: false then.
  bool step(double seconds) {
    const double left = seconds_left && !ignore_budget ? seconds_left() : kNever;
    if (seconds >= left) {
      clock += std::max(left, 0.0);
      return false;
    }
    clock += seconds;
    return true;
  }
};

class SimulatedFrames : public FrameSource {
 public:
  SimulatedFrames(double n, int width, SimulatedMachine& machine)
      : n_(n), pixels_(double(width) * double(width * 3 / 4)), machine_(machine) {}
  double axis_value() const override { return n_; }
  double pixels() const override { return pixels_; }
  double prepare_seconds(size_t index) const override { return index == 0 ? 0.0 : 1e-6 * n_; }
  std::map<std::string, double> counters(size_t index) const override {
    return {{index == 0 ? "triangles.setup" : "rays.primary", index == 0 ? n_ : pixels_}};
  }
  Expected<FrameTime> time_frame(size_t index) override {
    double t = (index == 0 ? kZCurve : kTCurve)(pixels_, n_) *
               std::exp(machine_.frame_noise * machine_.rng.normal()) * machine_.slowdown();
    // Under a constant load the two renderers of one round share the machine's state, but not
    // its effect: contention slows a memory-bound frame more than another.
    if (machine_.load) t *= index == 0 ? load_ : load_ * std::exp(0.1 * machine_.rng.normal());
    if (machine_.load && index == 0) load_ = 1.5 + machine_.rng.uniform();
    if (machine_.clock >= machine_.stall_at) {
      t += machine_.stall_seconds;
      machine_.stall_at = kNever;
    }
    if (!machine_.step(t)) return out_of_time_error("stopped at the budget's end");
    FrameTime out;
    out.seconds = t;
    return out;
  }

 private:
  double n_, pixels_;
  SimulatedMachine& machine_;
  double load_ = 2.0;
};

class SimulatedSession : public Session {
 public:
  explicit SimulatedSession(SimulatedMachine& machine) : machine_(machine) {}
  std::string kind() const override { return "process"; }
  Expected<std::unique_ptr<FrameSource>> prepare(const Family&, size_t n, int width) override {
    if (!machine_.step(1e-6 * double(n))) return out_of_time_error("stopped at the budget's end");
    return std::unique_ptr<FrameSource>(new SimulatedFrames(double(n), width, machine_));
  }
  void stop_steps_when_out_of_time(const std::function<double()>& seconds_left) override {
    machine_.seconds_left = seconds_left;
  }

 private:
  SimulatedMachine& machine_;
};

// A study of softraster and raytrace on tessphere on a SimulatedMachine.
struct SimulatedStudy {
  SimulatedMachine machine;
  StudyRequest request;
  StudyHooks hooks;

  SimulatedStudy(uint64_t seed, double budget, int replicates) {
    machine.rng = Rng(seed);
    request.scenes = {"builtin:tessphere"};
    request.renderers = {"softraster", "raytrace"};
    request.budget_seconds = budget;
    request.bootstrap_replicates = replicates;
    hooks.now = [this] { return machine.clock; };
    hooks.start_session = [this]() -> Expected<std::unique_ptr<Session>> {
      return std::unique_ptr<Session>(new SimulatedSession(machine));
    };
    hooks.probe = [this](double window) {
      machine.clock += window;
      SystemSnapshot s;
      s.known = true;
      s.cpus = 2;
      s.other_busy = machine.load || machine.slowdown() > 1 ? 0.9 : 0.02;
      return s;
    };
  }
  SimulatedStudy(const SimulatedStudy&) = delete;  // the hooks point at this one
};

// Every point holds one run per session at most, every renderer's runs of it in the same
// sessions.
void expect_one_run_per_session(const StudyResult& r) {
  std::map<std::tuple<std::string, double, int>, std::set<int>> sessions_of;  // scene, N, width
  for (const Measurement& m : r.points) {
    std::set<int> sessions;
    for (const study::Run& run : m.runs) {
      EXPECT_TRUE(sessions.insert(run.session).second)
          << m.renderer << " N=" << m.n << ": session " << run.session << " twice";
    }
    auto [it, fresh] = sessions_of.try_emplace({m.scene, m.scene_n, m.width}, sessions);
    if (!fresh) {
      EXPECT_EQ(it->second, sessions) << m.renderer << " N=" << m.n;
    }
  }
}

bool noted(const StudyResult& r, const std::string& words) {
  for (const std::string& note : r.notes)
    if (note.find(words) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(StudyRun, SweepsInFreshSessionsWithinTheBudget) {
  SimulatedStudy study(4, 600, 200);
  Expected<StudyResult> r = run_study(study.request, study.hooks);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_LE(r->elapsed_seconds, study.request.budget_seconds);
  size_t full_width = 0, narrower = 0;
  for (const Measurement& m : r->points) {
    (m.width == study.request.width ? full_width : narrower)++;
    // Every point in three sessions, five rounds each, no session twice.
    ASSERT_EQ(m.runs.size(), 3u) << m.renderer << " N=" << m.n << " width " << m.width << "\n"
                                 << study_markdown(*r);
    std::set<int> sessions;
    for (const study::Run& run : m.runs) {
      EXPECT_EQ(run.seconds.size(), 5u);
      sessions.insert(run.session);
      EXPECT_EQ(r->sessions.at(size_t(run.session)).kind, "process");
    }
    EXPECT_EQ(sessions.size(), 3u);
    EXPECT_FALSE(m.counters.empty());
  }
  EXPECT_GE(full_width, 2 * log_spaced(100, 1000000, 13).size());
  EXPECT_EQ(narrower, 3u * 4u * 2u);  // three N at four narrower widths, two renderers
  std::vector<Crossover> along_n;
  for (const Crossover& c : r->crossovers)
    if (c.axis != kPixelsAxis) along_n.push_back(c);
  ASSERT_EQ(along_n.size(), 1u) << study_markdown(*r);
  EXPECT_LT(std::fabs(std::log10(along_n[0].value / true_crossing())), 0.1);
  ASSERT_FALSE(r->checks.empty());
  for (const PredictionCheck& c : r->checks) EXPECT_NE(c.verdict, "fails") << c.why;
  EXPECT_EQ(r->check_points.size(), 2 * r->checks.size());
  EXPECT_TRUE(r->no_conclusion.empty());
  EXPECT_NE(study_json(*r).find("\"format\": \"rvr-study/2\""), std::string::npos);
}

// Something else runs for 6 of the 60 simulated seconds, doubling every frame's time: the runs
// measured then are found by their reference frames and measured again as the budget allows.
TEST(StudyRun, RunsMeasuredWhileTheMachineWasBusyAreMeasuredAgain) {
  SimulatedStudy study(6, 60, 200);
  study.machine.busy_from = 8;
  study.machine.busy_to = 14;
  Expected<StudyResult> r = run_study(study.request, study.hooks);
  ASSERT_TRUE(r.ok()) << r.error().message;
  expect_one_run_per_session(*r);
  bool still_busy = false;
  for (const Measurement& m : r->points)
    for (const study::Run& run : m.runs) still_busy |= run.busy;
  EXPECT_TRUE(noted(*r, "measured again"));
  EXPECT_EQ(still_busy, noted(*r, "were measured while the machine was busy"));
  for (const Measurement& m : r->points) {
    if (m.busy()) continue;
    const CostFn& truth = m.renderer == "softraster" ? kZCurve : kTCurve;
    EXPECT_LT(std::fabs(std::log(typical_seconds(m) / truth(m.pixels, m.n))), std::log(1.15))
        << m.renderer << " N=" << m.n << " " << m.width << " wide: off its curve";
  }
  ASSERT_FALSE(r->crossovers.empty()) << study_markdown(*r);
  EXPECT_LT(std::fabs(std::log10(r->crossovers[0].value / true_crossing())), 0.1);
}

// A load throughout the study, slowing every frame 1.5–2.5× from round to round: the probe
// sees it, every run is busy, and the paired ratios still find the crossover, with a wider
// interval than on the quiet machine.
TEST(StudyRun, ABusyMachineStillGetsAnAnswer) {
  SimulatedStudy quiet(12, 60, 300), busy(12, 60, 300);
  busy.machine.load = true;
  Expected<StudyResult> q = run_study(quiet.request, quiet.hooks);
  Expected<StudyResult> b = run_study(busy.request, busy.hooks);
  ASSERT_TRUE(q.ok() && b.ok());
  expect_one_run_per_session(*b);
  for (const Measurement& m : b->points) EXPECT_TRUE(m.busy());
  EXPECT_TRUE(b->no_conclusion.empty()) << b->no_conclusion;
  auto along_n = [](const StudyResult& r) -> const Crossover* {
    for (const Crossover& c : r.crossovers)
      if (c.axis != kPixelsAxis && c.measured) return &c;
    return nullptr;
  };
  const Crossover *cq = along_n(*q), *cb = along_n(*b);
  ASSERT_TRUE(cq && cb) << study_markdown(*b);
  EXPECT_LT(std::fabs(std::log10(cb->value / true_crossing())), 0.15);
  auto width = [](const Crossover* c) { return std::log(c->ci95.high / c->ci95.low); };
  EXPECT_GT(width(cb), width(cq));
  EXPECT_TRUE(noted(*b, "fitted to times measured while the machine was busy"));
}

// The budget is a limit: whatever it is, the measuring ends within it, and a budget too small
// for anything says so and concludes nothing, without an empty heading.
TEST(StudyRun, TheBudgetIsALimitThatHolds) {
  for (double budget : {1.0, 3.0, 12.0, 40.0}) {
    SimulatedStudy study(5, budget, 50);
    Expected<StudyResult> r = run_study(study.request, study.hooks);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_LE(r->elapsed_seconds, budget) << "budget " << budget;
  }
  SimulatedStudy tiny(5, 1.0, 50);
  Expected<StudyResult> r = run_study(tiny.request, tiny.hooks);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->no_conclusion.empty());
  const std::string md = study_markdown(*r);
  EXPECT_NE(md.find("## No conclusion"), std::string::npos) << md;
  EXPECT_NE(md.find("--budget"), std::string::npos) << md;
  for (size_t at = md.find("\n## "); at != std::string::npos; at = md.find("\n## ", at + 1)) {
    const size_t next = md.find("\n## ", at + 1);
    const std::string body = md.substr(at, next == std::string::npos ? next : next - at);
    EXPECT_GT(std::count(body.begin(), body.end(), '\n'), 2) << "empty heading: " << body;
  }
  const std::string html = study_html(*r);
  EXPECT_NE(html.find(r->no_conclusion.substr(0, 40)), std::string::npos);
}

// A frame far longer than any before it, started late in the sweep and in the prediction checks'
// last second: the session stops it at the budget's end, its run is dropped and said to be, and
// the study concludes from the runs before. Without the stop (ignore_budget) the measuring ends
// late.
TEST(StudyRun, AStepStillRunningAtTheBudgetsEndIsStopped) {
  const double budget = 600;
  SimulatedStudy undisturbed(4, budget, 100);
  Expected<StudyResult> u = run_study(undisturbed.request, undisturbed.hooks);
  ASSERT_TRUE(u.ok()) << u.error().message;
  ASSERT_FALSE(u->check_points.empty());
  const double end = u->elapsed_seconds;
  struct Case {
    double stall_at;
    const char* note;
  };
  for (Case c : {Case{0.5 * end, "ran out during the sweep"},
                 Case{end - 0.5, "ran out during the prediction checks"}}) {
    SimulatedStudy study(4, budget, 100);
    study.machine.stall_at = c.stall_at;
    study.machine.stall_seconds = budget;
    Expected<StudyResult> r = run_study(study.request, study.hooks);
    ASSERT_TRUE(r.ok()) << r.error().message;
    // Stopped 10 ms before the end, the time stopping a worker may take.
    EXPECT_LE(r->elapsed_seconds, budget) << c.note;
    EXPECT_GE(r->elapsed_seconds, budget - 0.011) << c.note;
    EXPECT_TRUE(noted(*r, c.note)) << c.note;
    expect_one_run_per_session(*r);
    for (const Measurement& m : r->points)
      for (const study::Run& run : m.runs) EXPECT_EQ(run.seconds.size(), 5u);
    EXPECT_FALSE(r->points.empty());

    SimulatedStudy late(4, budget, 100);
    late.machine.stall_at = c.stall_at;
    late.machine.stall_seconds = budget;
    late.machine.ignore_budget = true;
    Expected<StudyResult> l = run_study(late.request, late.hooks);
    ASSERT_TRUE(l.ok()) << l.error().message;
    EXPECT_GT(l->elapsed_seconds, budget + 1) << c.note << ": the plant is inert";
  }
}

TEST(StudyRun, RefusesBadInputBeforeAnyWork) {
  bool started = false;
  StudyHooks hooks;
  hooks.start_session = [&]() -> Expected<std::unique_ptr<Session>> {
    started = true;
    return internal_error("not reached");
  };
  auto refused = [&](const StudyRequest& r, const std::string& words) {
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
  r = ok;
  r.sessions = 2;
  refused(r, "--processes: must be >= 3");
  r = ok;
  r.noise_threshold = -0.1;
  refused(r, "--noise-threshold");
  EXPECT_FALSE(started);
}

TEST(StudyMarkdown, NumbersInPowersOfTen) {
  EXPECT_EQ(format_number(2.1e6), "2.1×10^6");
  EXPECT_EQ(format_number(123.456), "123");
  EXPECT_EQ(format_number(9.97e5), "1.0×10^6");
  EXPECT_EQ(format_number(1000), "1000");
  EXPECT_EQ(format_number(0.5), "0.5");
}

// Full mode: per renderer, family and effect, the range of the error over the points and its
// worst point; nothing when no point holds effect errors.
TEST(StudyMarkdown, EachTechniquesErrorIsItsRangeOverThePointsAndItsWorstPoint) {
  StudyResult r;
  r.scenes = {"effects"};
  r.axes["effects"] = "triangles";
  r.renderers = {"softraster", "raytrace"};
  r.mode = "full";
  EXPECT_TRUE(technique_error_sentences(r).empty());
  const double kInf = std::numeric_limits<double>::infinity();
  // PSNR, SSIM and pixels at three N: the worst PSNR at the middle one.
  const double psnr[] = {30, 20, 25}, ssim[] = {0.9, 0.8, 0.85}, pixels[] = {100, 200, 150};
  for (int k = 0; k < 3; ++k) {
    Measurement m;
    m.renderer = "softraster";
    m.scene = "effects";
    m.n = 1000.0 * (k + 1);
    m.width = 64;
    m.height = 48;
    m.effect_errors = {{"reflection", pixels[k], 0.1, psnr[k], ssim[k]}, {"csg", 10, 0, kInf, 1}};
    r.points.push_back(m);
    m.renderer = "raytrace";
    m.effect_errors.clear();
    r.points.push_back(m);
  }
  EXPECT_EQ(technique_error_sentences(r),
            (std::vector<std::string>{
                "softraster on effects, reflection: PSNR 20 to 30 dB, SSIM 0.8 to 0.9 in a mask "
                "of 100 to 200 pixels, over 3 points; worst at 2000 triangles, 64×48.",
                "softraster on effects, csg: PSNR ∞ dB, SSIM 1 in a mask of 10 pixels, over 3 "
                "points; worst at 1000 triangles, 64×48."}));
  EXPECT_NE(study_markdown(r).find("## Each technique's error"), std::string::npos);
  EXPECT_NE(study_html(r).find("<h2>Each technique's error</h2>"), std::string::npos);
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
  r.noise_threshold = 0.03;
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
  for (size_t at = html.find("<svg class=\"chart study-chart\""); at != std::string::npos;
       at = html.find("<svg class=\"chart study-chart\"", at + 1))
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

// The grey band of the range not measured never covers a measured point, in any chart: the
// main one, the pixel sweeps' and a study whose points were measured at the range's edges only.
TEST(StudyHtml, TheUnmeasuredBandNeverCoversAPoint) {
  StudyResult r = html_study();
  const size_t count = r.points.size();
  for (size_t i = 0; i < count; ++i)
    if (r.points[i].scene == "synthetic" && r.points[i].n < 1e5) {
      Measurement m = r.points[i];
      m.pixels = kP / 4;
      r.points.push_back(m);
    }
  auto numbers_after = [](const std::string& svg, size_t from, const std::string& name) {
    const size_t at = svg.find(" " + name + "=\"", from);
    return at == std::string::npos ? std::nan("") : std::stod(svg.substr(at + name.size() + 3));
  };
  size_t marks = 0;
  for (const std::string& chart : charts_of(study_html(r))) {
    std::vector<std::pair<double, double>> bands;
    for (size_t at = chart.find("<rect class=\"unmeasured\""); at != std::string::npos;
         at = chart.find("<rect class=\"unmeasured\"", at + 1)) {
      const double x = numbers_after(chart, at, "x");
      bands.push_back({x, x + numbers_after(chart, at, "width")});
    }
    for (size_t at = chart.find("<circle class=\"mark\""); at != std::string::npos;
         at = chart.find("<circle class=\"mark\"", at + 1)) {
      const double cx = numbers_after(chart, at, "cx");
      ++marks;
      for (const auto& [lo, hi] : bands)
        EXPECT_FALSE(cx > lo && cx < hi)
            << "a point at x " << cx << " under [" << lo << ", " << hi << "]";
    }
  }
  EXPECT_GT(marks, 0u);
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
      for (study::Run& run : m.runs)
        for (double& s : run.seconds) s /= 2;
      r.points.push_back(m);
    }
  std::vector<std::string> charts = charts_of(study_html(r));
  const size_t per_scene = log_spaced(100, 1000000, 13).size();
  ASSERT_EQ(charts.size(), r.scenes.size() + per_scene);
  for (const std::string& name : r.renderers) {
    EXPECT_EQ(marks_of(charts[0], name), per_scene) << "the main chart: one pixel count";
    EXPECT_EQ(marks_of(charts[1], name), 2u) << "against pixels: one point at each";
    EXPECT_EQ(occurrences(charts[1], "<path class=\"model fits\" data-renderer=\"" + name + "\""),
              1u)
        << name;
  }
}

// A model file grown by copies: the triangles grow as the copies, the floor stays one, and the
// framed camera sees every copy's centre (the projection computed here from the camera's frame).
TEST(StudyGrid, CopiesGrowTheTrianglesAndStayInView) {
  Scene base;
  base.source = "test";
  base.image.width = 64;
  base.image.height = 48;
  Object floor;
  floor.type = ObjectType::Plane;
  base.objects.push_back(floor);
  Object tri;
  tri.type = ObjectType::Triangles;
  tri.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  tri.mesh.triangles = {{0, 1, 2}};
  base.objects.push_back(tri);
  base.camera.eye = {0.5f, 0.5f, 3.0f};
  base.camera.target = {0.5f, 0.5f, 0.0f};
  for (size_t copies : {1u, 5u, 16u}) {
    Expected<Scene> grid = grid_of_copies(base, copies);
    ASSERT_TRUE(grid.ok()) << grid.error().message;
    size_t planes = 0, meshes = 0;
    for (const Object& o : grid->objects) {
      planes += o.type == ObjectType::Plane;
      meshes += o.type == ObjectType::Triangles;
    }
    EXPECT_EQ(planes, 1u);
    EXPECT_EQ(meshes, copies);
    CameraFrame f = make_camera_frame(grid->camera, 64, 48);
    for (const Object& o : grid->objects) {
      if (o.type != ObjectType::Triangles) continue;
      glm::vec3 centre = (o.mesh.positions[0] + o.mesh.positions[1] + o.mesh.positions[2]) / 3.0f;
      glm::vec3 v = centre - f.eye;
      float depth = glm::dot(v, f.forward);
      ASSERT_GT(depth, 0.0f);
      EXPECT_LE(std::fabs(glm::dot(v, f.right)) / depth, f.tan_half_fov_y * f.aspect) << o.name;
      EXPECT_LE(std::fabs(glm::dot(v, f.up)) / depth, f.tan_half_fov_y) << o.name;
    }
  }
  Scene empty = base;
  empty.objects.resize(1);  // the floor alone
  EXPECT_FALSE(grid_of_copies(empty, 4).ok());
}

// A model file is a family: 1 … K copies, K so that they hold about 2×10^6 triangles.
TEST(StudyGrid, AModelFileIsAFamily) {
  Expected<Family> f = find_family(RVR_SOURCE_DIR "/scenes/models/torus.obj");
  ASSERT_TRUE(f.ok()) << f.error().message;
  EXPECT_EQ(f->name, "torus.obj");
  EXPECT_EQ(f->axis, "triangles");
  EXPECT_EQ(f->low, 1u);
  Expected<Scene> one = load_scene(f->source);
  ASSERT_TRUE(one.ok());
  double per_copy = double(one->triangle_count());
  EXPECT_LE(double(f->high) * per_copy, kFileFamilyTriangles);
  EXPECT_GT(double(f->high + 1) * per_copy, kFileFamilyTriangles);
  EXPECT_FALSE(find_family("no-such-file.obj").ok());
}

namespace {

// A whole study as run_study leaves it before conclude(): softraster and raytrace on
// tessphere at 13 N in 3 sessions, every field study.json holds set.
StudyResult synthetic_study(uint64_t seed) {
  Rng rng(seed);
  StudyResult r;
  r.scenes = {"tessphere"};
  r.axes["tessphere"] = "triangles";
  r.renderers = {"softraster", "raytrace"};
  r.width = 1024;
  r.height = 768;
  r.mode = "local";
  r.budget_seconds = 60;
  r.elapsed_seconds = 41.5;
  r.repetitions = 5;
  r.sessions_per_point = 3;
  r.noise_threshold = 0.03;
  r.seed = 7;
  r.run_id = fmt::format("run-{}", seed);
  r.bootstrap_replicates = 200;
  r.command = "rvr study builtin:tessphere -o out";
  r.machine = {"Test CPU 9000", 2, "avx2 (the widest this CPU runs)", {{"rvr", "0.1"}}};
  r.notes = {"tessphere: the sweep stopped below N=1000000"};
  r.system_before.known = true;
  r.system_before.cpus = 2;
  r.system_before.load1 = 0.5;
  r.system_before.mhz = 2600;
  r.system_before.governor = "performance";
  r.system_after = r.system_before;
  r.system_after.at = 41.5;
  for (int s = 0; s < 3; ++s) r.sessions.push_back({"process", r.run_id, r.system_before});
  Noise noise;
  noise.frame = 0.03;
  for (size_t n : log_spaced(100, 1000000, 13))
    for (Measurement& m : synthetic_point(r.renderers, {kZCurve, kTCurve}, kP, double(n), 3, 5,
                                          noise, rng, "tessphere")) {
      m.width = r.width;
      m.height = r.height;
      m.counters = {{"triangles.setup", double(n)}, {"rays.primary", kP}};
      for (study::Run& run : m.runs) {
        run.order = {0, 1, 1, 0, 1};
        run.prepare_seconds = 1e-7 * double(n);
        run.reference_ratio = 1.0 + 0.01 * double(r.points.size() % 7);
      }
      r.points.push_back(m);
    }
  return r;
}

StudyResult read_back(const StudyResult& r) {
  Expected<StudyResult> back = read_study_json(study_json(r), "study.json");
  EXPECT_TRUE(back.ok()) << back.error().message;
  return back.ok() ? *back : StudyResult{};
}

// The study with only the points at every `count`-th N from the `index`-th, as shard
// index/count of it.
StudyResult shard_of(const StudyResult& whole, size_t index, size_t count) {
  StudyResult part = whole;
  part.shard = Shard{index, count};
  part.run_id = fmt::format("{}-shard-{}", whole.run_id, index);
  part.points.clear();
  for (size_t i = 0; i < whole.points.size(); ++i)
    if (in_shard(i / whole.renderers.size(), *part.shard)) part.points.push_back(whole.points[i]);
  return part;
}

void expect_same_conclusions(const StudyResult& a, const StudyResult& b) {
  ASSERT_EQ(a.models.size(), b.models.size());
  for (size_t i = 0; i < a.models.size(); ++i) {
    const ModelFit &fa = a.models[i].fits.at("tessphere"), &fb = b.models[i].fits.at("tessphere");
    EXPECT_EQ(fa.fits, fb.fits);
    ASSERT_EQ(fa.coefficients.size(), fb.coefficients.size());
    for (size_t k = 0; k < fa.coefficients.size(); ++k)
      EXPECT_DOUBLE_EQ(fa.coefficients[k].value, fb.coefficients[k].value) << a.models[i].name;
  }
  ASSERT_EQ(a.crossovers.size(), b.crossovers.size());
  for (size_t i = 0; i < a.crossovers.size(); ++i)
    EXPECT_DOUBLE_EQ(a.crossovers[i].value, b.crossovers[i].value);
}

}  // namespace

// Everything conclude() and study.md need comes back: concluded again, the study is written
// out the same, byte for byte.
TEST(StudyJsonRead, RoundTripsEveryFieldConcludeNeeds) {
  StudyResult r = synthetic_study(31);
  r.interrupted = true;
  r.shard = Shard{1, 4};
  r.merged_runs = {"a", "b"};
  r.points[5].runs[1].busy = true;
  r.points[5].runs[1].reference_ratio = 1.6;
  r.points[6].runs[0].phases["zbuffer"] = {1, 2, 3, 4, 5};
  const double kInf = std::numeric_limits<double>::infinity();
  r.points[4].effect_errors = {{"reflection", 162, 0.015, 36.5, 0.996}, {"csg", 7, 0, kInf, 1}};
  conclude(r, {r.bootstrap_replicates, r.seed});
  StudyResult back = read_back(r);
  EXPECT_EQ(back.scenes, r.scenes);
  EXPECT_EQ(back.axes, r.axes);
  EXPECT_EQ(back.renderers, r.renderers);
  EXPECT_EQ(back.width, r.width);
  EXPECT_EQ(back.height, r.height);
  EXPECT_EQ(back.mode, r.mode);
  EXPECT_EQ(back.budget_seconds, r.budget_seconds);
  EXPECT_EQ(back.elapsed_seconds, r.elapsed_seconds);
  EXPECT_EQ(back.repetitions, r.repetitions);
  EXPECT_EQ(back.sessions_per_point, r.sessions_per_point);
  EXPECT_EQ(back.noise_threshold, r.noise_threshold);
  EXPECT_EQ(back.seed, r.seed);
  EXPECT_EQ(back.run_id, r.run_id);
  EXPECT_EQ(back.merged_runs, r.merged_runs);
  EXPECT_EQ(back.bootstrap_replicates, r.bootstrap_replicates);
  EXPECT_EQ(back.command, r.command);
  EXPECT_EQ(back.machine.cpu, r.machine.cpu);
  EXPECT_EQ(back.machine.threads, r.machine.threads);
  EXPECT_EQ(back.machine.kernels, r.machine.kernels);
  EXPECT_EQ(back.machine.versions, r.machine.versions);
  EXPECT_EQ(back.system_after.governor, "performance");
  EXPECT_EQ(back.system_after.at, 41.5);
  ASSERT_EQ(back.sessions.size(), r.sessions.size());
  EXPECT_EQ(back.sessions[2].kind, "process");
  EXPECT_EQ(back.notes, r.notes);
  EXPECT_TRUE(back.interrupted);
  ASSERT_TRUE(back.shard.has_value());
  EXPECT_EQ(back.shard->index, 1u);
  EXPECT_EQ(back.shard->count, 4u);
  ASSERT_EQ(back.points.size(), r.points.size());
  for (size_t i = 0; i < r.points.size(); ++i) {
    const Measurement &a = back.points[i], &b = r.points[i];
    EXPECT_EQ(a.renderer, b.renderer);
    EXPECT_EQ(a.scene, b.scene);
    EXPECT_EQ(a.scene_n, b.scene_n);
    EXPECT_EQ(a.n, b.n);
    EXPECT_EQ(a.pixels, b.pixels);
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.counters, b.counters);
    ASSERT_EQ(a.effect_errors.size(), b.effect_errors.size());
    for (size_t k = 0; k < a.effect_errors.size(); ++k) {
      EXPECT_EQ(a.effect_errors[k].effect, b.effect_errors[k].effect);
      EXPECT_EQ(a.effect_errors[k].pixels, b.effect_errors[k].pixels);
      EXPECT_EQ(a.effect_errors[k].rmse, b.effect_errors[k].rmse);
      EXPECT_EQ(a.effect_errors[k].psnr_db, b.effect_errors[k].psnr_db);  // +inf too
      EXPECT_EQ(a.effect_errors[k].ssim, b.effect_errors[k].ssim);
    }
    ASSERT_EQ(a.runs.size(), b.runs.size());
    for (size_t k = 0; k < a.runs.size(); ++k) {
      EXPECT_EQ(a.runs[k].session, b.runs[k].session);
      EXPECT_EQ(a.runs[k].seconds, b.runs[k].seconds);
      EXPECT_EQ(a.runs[k].order, b.runs[k].order);
      EXPECT_EQ(a.runs[k].phases, b.runs[k].phases);
      EXPECT_EQ(a.runs[k].prepare_seconds, b.runs[k].prepare_seconds);
      EXPECT_EQ(a.runs[k].reference_ratio, b.runs[k].reference_ratio);
      EXPECT_EQ(a.runs[k].busy, b.runs[k].busy);
    }
  }
  EXPECT_TRUE(back.models.empty()) << "conclusions are computed again, not read";
  conclude(back, {back.bootstrap_replicates, back.seed});
  EXPECT_EQ(study_json(back), study_json(r));
  r.shard.reset();
  EXPECT_FALSE(read_back(r).shard.has_value());
}

// The hybrid's z-buffer/trace split: the medians of each phase's repetitions at the smallest and
// largest N at full width, kept through study.json and read back.
TEST(StudyConclusions, TheHybridsSplitIsTheMedianOfEachPhase) {
  StudyResult r = synthetic_study(30);
  r.renderers = {"softraster", "hybrid_soft"};
  r.points.clear();
  for (double n : {100.0, 10000.0, 1000000.0})
    for (const std::string& name : r.renderers) {
      Measurement m;
      m.renderer = name;
      m.scene = "tessphere";
      m.scene_n = m.n = n;
      m.width = 1024;
      m.height = 768;
      m.pixels = kP;
      study::Run run;
      run.seconds = {5e-3, 6e-3, 7e-3, 8e-3, 9e-3};
      run.order = {0, 1, 0, 1, 0};
      if (name == "hybrid_soft") {
        run.phases["zbuffer"] = {1e-3, 3e-3, 2e-3, 5e-3, 4e-3};  // median 3 ms
        run.phases["trace"] = {2e-3, 1e-3, 3e-3, 1e-3, 6e-3};    // median 2 ms
      }
      m.runs.push_back(run);
      r.points.push_back(m);
    }
  conclude(r, {50, 1});
  ASSERT_EQ(r.splits.size(), 2u);
  EXPECT_EQ(r.splits[0].renderer, "hybrid_soft");
  EXPECT_EQ(r.splits[0].n, 100.0);
  EXPECT_EQ(r.splits[1].n, 1000000.0);
  EXPECT_DOUBLE_EQ(r.splits[0].zbuffer_seconds, 3e-3);
  EXPECT_DOUBLE_EQ(r.splits[0].trace_seconds, 2e-3);
  EXPECT_DOUBLE_EQ(r.splits[0].zbuffer_share, 0.6);
  Expected<StudyResult> back = read_study_json(study_json(r), "split.json");
  ASSERT_TRUE(back.ok()) << back.error().message;
  StudyResult again = *back;
  conclude(again, {50, 1});
  ASSERT_EQ(again.splits.size(), 2u);
  EXPECT_DOUBLE_EQ(again.splits[1].zbuffer_share, 0.6);
  EXPECT_NE(study_markdown(r).find("(60% z-buffer)"), std::string::npos) << study_markdown(r);
}

TEST(StudyJsonRead, RefusesMalformedInputNamingFileAndPath) {
  StudyResult r = synthetic_study(32);
  conclude(r, {50, 1});
  const nlohmann::json good = nlohmann::json::parse(study_json(r));
  auto refused = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& words) {
    nlohmann::json doc = good;
    edit(doc);
    Expected<StudyResult> out = read_study_json(doc.dump(), "d/study.json");
    ASSERT_FALSE(out.ok()) << words;
    EXPECT_EQ(out.error().kind, ErrorKind::BadInput);
    EXPECT_NE(out.error().message.find(words), std::string::npos) << out.error().message;
  };
  refused([](nlohmann::json& d) { d["pointz"] = 1; }, "d/study.json: pointz: unknown key");
  refused([](nlohmann::json& d) { d["format"] = "rvr-study/1"; },
          "d/study.json: format: must be \"rvr-study/2\"");
  refused([](nlohmann::json& d) { d.erase("machine"); }, "d/study.json: machine: is required");
  refused([](nlohmann::json& d) { d["points"][3]["runs"][0]["seconds"][1] = -1.0; },
          "d/study.json: points[3].runs[0].seconds[1]: must be >= 0");
  refused([](nlohmann::json& d) { d["points"][0]["renderer"] = "embree"; },
          "points[0].renderer: string \"embree\" is not in renderer_order");
  refused([](nlohmann::json& d) { d["points"][2]["runs"][1]["order"] = {0}; },
          "points[2].runs[1].order:");
  refused([](nlohmann::json& d) { d["points"][2]["runs"][1]["session"] = 99; },
          "points[2].runs[1].session: must index sessions");
  refused([](nlohmann::json& d) { d["points"][2]["runs"][1]["session"] = 0; },
          "already has a run at this point");
  refused([](nlohmann::json& d) { d["points"][2]["runs"] = nlohmann::json::array(); },
          "points[2].runs: must hold at least one run");
  refused([](nlohmann::json& d) { d["width"] = "wide"; }, "width: must be a whole number");
  refused([](nlohmann::json& d) { d["renderer_order"][1] = "nosuch"; }, "renderer_order[1]:");
  refused([](nlohmann::json& d) { d["shard"] = {{"index", 4}, {"count", 4}}; }, "shard.index");
  refused([](nlohmann::json& d) { d["scenes"][0]["axis"] = "depth"; }, "scenes[0].axis");
  refused([](nlohmann::json& d) { d["sessions"][0]["kind"] = "thread"; }, "sessions[0].kind");
  refused([](nlohmann::json& d) { d["run_id"] = ""; }, "run_id: must not be empty");
  Expected<StudyResult> syntax = read_study_json("{\"format\": ", "d/study.json");
  ASSERT_FALSE(syntax.ok());
  EXPECT_NE(syntax.error().message.find("d/study.json: JSON syntax"), std::string::npos);
}

TEST(StudyShard, ShardsCoverThePlanExactlyOnce) {
  for (size_t count = 1; count <= 9; ++count)
    for (size_t i = 0; i < 40; ++i) {
      int owners = 0;
      for (size_t index = 0; index < count; ++index) owners += in_shard(i, Shard{index, count});
      EXPECT_EQ(owners, 1) << "point " << i << " of shards of " << count;
    }
  Expected<Shard> s = parse_shard("3/8");
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->index, 3u);
  EXPECT_EQ(s->count, 8u);
  for (const char* bad : {"8/8", "-1/8", "1/0", "a/b", "3", "3/8x", "/8", ""}) {
    Expected<Shard> out = parse_shard(bad);
    ASSERT_FALSE(out.ok()) << bad;
    EXPECT_EQ(out.error().kind, ErrorKind::BadInput);
    EXPECT_EQ(out.error().message.rfind("--shard: ", 0), 0u) << out.error().message;
  }
}

// Shards 0 and 1 of 2, written and read back, pool into the study that measured every point:
// the same models and crossovers.
TEST(StudyMerge, TwoHalvesGiveTheModelsOfTheWhole) {
  StudyResult whole = synthetic_study(33);
  conclude(whole, {whole.bootstrap_replicates, whole.seed});
  std::vector<StudySource> halves;
  for (size_t i = 0; i < 2; ++i)
    halves.push_back({"shard-" + std::to_string(i), read_back(shard_of(whole, i, 2))});
  Expected<std::vector<MachineGroup>> merged = merge_studies(halves);
  ASSERT_TRUE(merged.ok()) << merged.error().message;
  ASSERT_EQ(merged->size(), 1u);
  StudyResult m = (*merged)[0].study;
  EXPECT_EQ(m.points.size(), whole.points.size());
  EXPECT_FALSE(m.shard.has_value());
  EXPECT_EQ(m.budget_seconds, 2 * whole.budget_seconds);
  EXPECT_EQ(m.merged_runs.size(), 2u);
  // Each half's sessions are the merged study's: a point keeps its three runs.
  EXPECT_EQ(m.sessions.size(), 2 * whole.sessions.size());
  for (const Measurement& p : m.points) EXPECT_EQ(p.runs.size(), 3u);
  ASSERT_FALSE(whole.crossovers.empty());
  // The runs renumbered are the same runs: the comparisons do not change.
  for (Measurement& p : m.points)
    for (study::Run& run : p.runs) run.session %= 3;
  m.sessions.resize(3);
  m.models.clear(), m.crossovers.clear(), m.dominance.clear(), m.comparisons.clear();
  m.scaling.clear(), m.costs.clear(), m.splits.clear();
  conclude(m, {whole.bootstrap_replicates, whole.seed});
  expect_same_conclusions(m, whole);
  for (const std::string& note : m.notes) EXPECT_EQ(note.find("missing"), std::string::npos);

  std::vector<StudySource> one_half = {halves[0]};
  Expected<std::vector<MachineGroup>> partial = merge_studies(one_half);
  ASSERT_TRUE(partial.ok());
  EXPECT_TRUE(noted((*partial)[0].study, "shard 1 of 2 missing")) << "a missing shard is not noted";
}

// Two studies that measured the same point: each one's runs are runs of the merged point, a
// level of their own (six sessions, not thirty frames in three).
TEST(StudyMerge, APointMeasuredByTwoStudiesKeepsEachStudysRuns) {
  StudyResult a = synthetic_study(34), b = synthetic_study(35);
  Expected<std::vector<MachineGroup>> merged = merge_studies({{"a", a}, {"b", b}});
  ASSERT_TRUE(merged.ok()) << merged.error().message;
  const StudyResult& m = (*merged)[0].study;
  ASSERT_EQ(m.points.size(), a.points.size());
  EXPECT_EQ(m.sessions.size(), 6u);
  for (size_t i = 0; i < a.points.size(); ++i) {
    ASSERT_EQ(m.points[i].runs.size(), 6u);
    EXPECT_EQ(m.points[i].runs[0].seconds, a.points[i].runs[0].seconds);
    EXPECT_EQ(m.points[i].runs[3].seconds, b.points[i].runs[0].seconds);
    EXPECT_EQ(m.points[i].runs[3].session, 3);
  }
  StudyResult moved = b;
  moved.points[0].n += 1;
  Expected<std::vector<MachineGroup>> clash = merge_studies({{"a", a}, {"b", moved}});
  ASSERT_FALSE(clash.ok());
  EXPECT_NE(clash.error().message.find("not the same point"), std::string::npos);
  StudyResult wider = b;
  wider.width = 2048;
  Expected<std::vector<MachineGroup>> sizes = merge_studies({{"a", a}, {"b", wider}});
  ASSERT_FALSE(sizes.ok());
  EXPECT_NE(sizes.error().message.find("one image size"), std::string::npos);
}

// A study merged twice, or with a merged copy of itself, would narrow the intervals with no new
// measurement: refused, and so is a copy under another run id.
TEST(StudyMerge, RefusesAStudyItAlreadyHolds) {
  StudyResult a = synthetic_study(36), b = synthetic_study(37);
  Expected<std::vector<MachineGroup>> twice = merge_studies({{"a", a}, {"a-again", a}});
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.error().message.find("a-again: holds the measurements of study run-36"),
            std::string::npos)
      << twice.error().message;
  Expected<std::vector<MachineGroup>> ab = merge_studies({{"a", a}, {"b", b}});
  ASSERT_TRUE(ab.ok());
  StudyResult merged = read_back((*ab)[0].study);
  Expected<std::vector<MachineGroup>> self = merge_studies({{"merged", merged}, {"a", a}});
  ASSERT_FALSE(self.ok());
  EXPECT_NE(self.error().message.find("already merged from merged"), std::string::npos)
      << self.error().message;
  StudyResult renamed = a;
  renamed.run_id = "another";
  Expected<std::vector<MachineGroup>> copy = merge_studies({{"a", a}, {"renamed", renamed}});
  ASSERT_FALSE(copy.ok());
  EXPECT_NE(copy.error().message.find("the same measurement twice"), std::string::npos)
      << copy.error().message;
}

// Another machine type (here: other SIMD kernels) or another mode is concluded apart and
// compared side by side.
TEST(StudyMerge, DifferentKernelsAreNotPooled) {
  StudyResult avx2 = synthetic_study(35), avx512 = synthetic_study(36), full = synthetic_study(37),
              avx2b = synthetic_study(38);
  avx512.machine.kernels = "avx512 (the widest this CPU runs)";
  full.mode = "full";
  Expected<std::vector<MachineGroup>> merged =
      merge_studies({{"x", avx2}, {"y", avx512}, {"z", full}, {"x2", avx2b}});
  ASSERT_TRUE(merged.ok()) << merged.error().message;
  ASSERT_EQ(merged->size(), 3u);
  const std::vector<MachineGroup>& g = *merged;
  EXPECT_EQ(g[0].sources, (std::vector<std::string>{"x", "x2"}));
  EXPECT_EQ(g[1].sources, std::vector<std::string>{"y"});
  EXPECT_EQ(g[2].sources, std::vector<std::string>{"z"});
  EXPECT_EQ(g[1].study.points.size(), avx512.points.size());
  EXPECT_EQ(g[1].study.machine.kernels, avx512.machine.kernels);
  EXPECT_EQ(g[0].slug, "test-cpu-9000-2t-avx2-local");
  EXPECT_EQ(g[1].slug, "test-cpu-9000-2t-avx512-local");
  EXPECT_EQ(g[2].slug, "test-cpu-9000-2t-avx2-full");
  std::string md = comparison_markdown(g);
  EXPECT_NE(md.find("| tessphere | raytrace vs softraster | triangles | crossover "),
            std::string::npos)
      << md;
  for (const MachineGroup& group : g) EXPECT_NE(md.find(group.label), std::string::npos) << md;
}

// Shards 0..2 of 3 of a sweep of two families, with budget to spare, measure every planned
// point exactly once between them and nothing else (no points near crossovers); merged, they
// hold the plan.
TEST(StudyRun, ShardsMeasureEveryPlannedPointOnce) {
  SimulatedStudy study(9, 1e5, 50);
  StudyRequest& request = study.request;
  StudyHooks& hooks = study.hooks;
  request.scenes = {"builtin:tessphere", "builtin:occluders"};
  using Key = std::tuple<std::string, double, int>;  // family, N, width
  std::map<Key, int> planned;
  for (const char* family : {"tessphere", "occluders"})
    for (const PlannedPoint& p : planned_points(*find_family(family), request.width))
      planned[{family, double(p.n), p.width}] = 0;
  std::vector<StudySource> shards;
  for (size_t i = 0; i < 3; ++i) {
    request.shard = Shard{i, 3};
    Expected<StudyResult> r = run_study(request, hooks);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_TRUE(r->shard.has_value());
    EXPECT_EQ(r->shard->index, i);
    EXPECT_TRUE(r->checks.empty()) << "a shard's crossovers are checked";
    ASSERT_FALSE(r->notes.empty());
    EXPECT_EQ(r->notes[0].rfind(fmt::format("shard {}/3: ", i), 0), 0u) << r->notes[0];
    for (const Measurement& m : r->points) {
      if (m.renderer != "softraster") continue;
      auto it = planned.find({m.scene, m.scene_n, m.width});
      ASSERT_NE(it, planned.end())
          << "not planned: " << m.scene << " " << m.scene_n << " " << m.width;
      ++it->second;
    }
    shards.push_back({fmt::format("shard-{}", i), *r});
  }
  for (const auto& [key, times] : planned)
    EXPECT_EQ(times, 1) << std::get<0>(key) << " N=" << std::get<1>(key) << " w"
                        << std::get<2>(key);
  Expected<std::vector<MachineGroup>> merged = merge_studies(shards);
  ASSERT_TRUE(merged.ok()) << merged.error().message;
  ASSERT_EQ(merged->size(), 1u);
  EXPECT_EQ((*merged)[0].study.points.size(), 2 * planned.size());

  request.shard.reset();
  Expected<StudyResult> whole = run_study(request, hooks);
  ASSERT_TRUE(whole.ok());
  EXPECT_FALSE(whole->shard.has_value());
  EXPECT_GT(whole->points.size(), 2 * planned.size()) << "the whole adds points near crossovers";
}

// A model with no positive time over a chart's x range cannot be drawn on a log axis: the chart
// says so in its place (a label naming the renderer), while a model positive somewhere is drawn
// as a path over the positive part only.
TEST(StudyChart, AModelWithNoPositiveTimeIsSaidNotSilentlyLeftOut) {
  ChartSpec spec;
  spec.id = "c";
  spec.title = "t";
  spec.x_label = "N";
  spec.y_label = "s";
  spec.swept_low = 10;
  spec.swept_high = 1e4;
  ChartSeries below, crossing;
  below.name = "below";
  below.colour = "#111";
  below.points = {{10, 1e-3, 1e-3, 1e-3, ""}, {1e4, 2e-3, 2e-3, 2e-3, ""}};
  below.model = [](double x) { return 1e-3 - 1e-6 * x - 1e-2; };  // negative everywhere
  crossing = below;
  crossing.name = "crossing";
  crossing.fits = true;
  crossing.model = [](double x) { return 1e-6 * x - 1e-4; };  // positive above x = 100
  spec.series = {below, crossing};
  const std::string svg = loglog_chart_svg(spec);
  auto count = [&](const std::string& what) {
    size_t n = 0;
    for (size_t at = svg.find(what); at != std::string::npos; at = svg.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("class=\"model-label model-not-positive\""), 1u) << svg;
  EXPECT_EQ(count("below: model not positive over this range (does not fit)"), 1u);
  EXPECT_EQ(count("<path class=\"model no-fit\" data-renderer=\"below\""), 0u);
  EXPECT_EQ(count("<path class=\"model fits\" data-renderer=\"crossing\""), 1u);
  EXPECT_EQ(count("crossing: model not positive"), 0u);
}
