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
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "rvr/shared/camera.h"
#include "rvr/shared/expected.h"
#include "rvr/shared/scene.h"
#include "rvr/shared/scene_loader.h"
#include "rvr/shared/texture.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/grid_of_copies.h"
#include "rvr/study/least_squares.h"
#include "rvr/study/measurement.h"
#include "rvr/study/merge.h"
#include "rvr/study/run_study.h"
#include "rvr/study/study.h"
#include "rvr/study/study_html.h"
#include "rvr/study/study_json.h"
#include "rvr/study/study_markdown.h"
#include "rvr/study/sweep_plan.h"
#include "loglog_chart.h"

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
  // Frames started while the clock is in [busy_from, busy_to) take twice as long: something
  // else is running.
  SimulatedFrames(double n, int width, double& clock, Rng& rng, double busy_from = 0,
                  double busy_to = 0)
      : n_(n),
        pixels_(double(width) * (width * 3 / 4)),
        clock_(clock),
        rng_(rng),
        busy_from_(busy_from),
        busy_to_(busy_to) {
    clock_ += 1e-6 * n;
  }
  double axis_value() const override { return n_; }
  double pixels() const override { return pixels_; }
  Expected<double> time_frame(size_t index) override {
    double t = (index == 0 ? kZCurve : kTCurve)(pixels_, n_) * std::exp(0.03 * rng_.normal());
    if (clock_ >= busy_from_ && clock_ < busy_to_) t *= 2;
    clock_ += t;
    return t;
  }

 private:
  double n_, pixels_;
  double& clock_;
  Rng& rng_;
  double busy_from_, busy_to_;
};

// A study of softraster and raytrace on tessphere whose frames are SimulatedFrames on a
// simulated clock (busy between busy_from and busy_to).
struct SimulatedStudy {
  double clock = 0;
  Rng rng;
  StudyRequest request;
  StudyHooks hooks;

  SimulatedStudy(uint64_t seed, double budget, int replicates, double busy_from = 0,
                 double busy_to = 0)
      : rng(seed) {
    request.scenes = {"builtin:tessphere"};
    request.renderers = {"softraster", "raytrace"};
    request.budget_seconds = budget;
    request.bootstrap_replicates = replicates;
    hooks.now = [this] { return clock; };
    hooks.prepare = [this, busy_from, busy_to](
                        const Family&, size_t n,
                        int width) -> Expected<std::unique_ptr<FrameSource>> {
      return std::unique_ptr<FrameSource>(
          new SimulatedFrames(double(n), width, clock, rng, busy_from, busy_to));
    };
  }
  SimulatedStudy(const SimulatedStudy&) = delete;  // the hooks point at this one
};

}  // namespace

TEST(StudyRun, SweepsWithinTheBudgetAndRefinesNearTheCrossover) {
  SimulatedStudy study(4, 30, 200);
  StudyRequest& request = study.request;
  StudyHooks& hooks = study.hooks;
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
  // The crossover along N checked after the fit, below and above it, the z-buffer faster below.
  ASSERT_EQ(r->checks.size(), 2u);
  for (const PredictionCheck& c : r->checks) {
    const bool below = c.at < c.crossover;
    EXPECT_NEAR(std::log10(c.at / c.crossover), below ? -std::log10(3.0) : std::log10(3.0), 0.1);
    const bool z_faster = kZCurve(kP, c.at) < kTCurve(kP, c.at);  // the truth at that N
    EXPECT_EQ(c.predicted_faster, z_faster ? "softraster" : "raytrace");
    EXPECT_TRUE(c.holds) << c.at;
  }
  EXPECT_NE(study_json(*r).find("\"format\": \"rvr-study/1\""), std::string::npos);
}

// Something else runs for 3 of the 30 simulated seconds, doubling every frame's time: the points
// measured then are found by their reference frames and measured again as the budget allows;
// every point left in the fits is on its curve, and those still busy are said to be.
TEST(StudyRun, PointsMeasuredWhileTheMachineWasBusyAreMeasuredAgain) {
  SimulatedStudy study(6, 30, 200, 4, 7);
  StudyRequest& request = study.request;
  StudyHooks& hooks = study.hooks;
  Expected<StudyResult> r = run_study(request, hooks);
  ASSERT_TRUE(r.ok()) << r.error().message;
  bool still_busy = false;
  for (const Measurement& m : r->points) {
    const CostFn& truth = m.renderer == "softraster" ? kZCurve : kTCurve;
    still_busy |= m.busy;
    if (m.busy) continue;
    EXPECT_LT(std::fabs(std::log(typical_seconds(m) / truth(m.pixels, m.n))), std::log(1.15))
        << m.renderer << " N=" << m.n << " " << m.width << " wide: off its curve";
  }
  auto noted = [&](const std::string& words) {
    for (const std::string& note : r->notes)
      if (note.find(words) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(noted("measured again"));
  EXPECT_EQ(still_busy, noted("left out of the fits"));
  ASSERT_FALSE(r->crossovers.empty()) << study_markdown(*r);
  EXPECT_LT(std::fabs(std::log10(r->crossovers[0].value / true_crossing())), 0.1);
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
// tessphere at 13 N, every field study.json holds set.
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
  r.seed = 7;
  r.bootstrap_replicates = 200;
  r.command = "rvr study builtin:tessphere -o out";
  r.machine = {"Test CPU 9000", 2, "avx2 (the widest this CPU runs)", {{"rvr", "0.1"}}};
  r.notes = {"tessphere: the sweep stopped below N=1000000"};
  for (size_t n : log_spaced(100, 1000000, 13))
    for (const std::string& name : r.renderers) {
      Measurement m =
          synthetic(name, name == "softraster" ? kZCurve : kTCurve, kP, double(n), 5, 0.03, rng);
      m.scene = "tessphere";
      m.width = r.width;
      m.height = r.height;
      m.order = {0, 1, 1, 0, 1};
      m.reference_ratio = 1.0 + 0.01 * double(r.points.size() % 7);
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
    for (size_t k = 0; k < fa.coefficients.size(); ++k) {
      EXPECT_DOUBLE_EQ(fa.coefficients[k].value, fb.coefficients[k].value) << a.models[i].name;
      EXPECT_DOUBLE_EQ(fa.coefficients[k].ci95.low, fb.coefficients[k].ci95.low);
      EXPECT_DOUBLE_EQ(fa.coefficients[k].ci95.high, fb.coefficients[k].ci95.high);
    }
  }
  ASSERT_EQ(a.crossovers.size(), b.crossovers.size());
  for (size_t i = 0; i < a.crossovers.size(); ++i) {
    EXPECT_DOUBLE_EQ(a.crossovers[i].value, b.crossovers[i].value);
    EXPECT_DOUBLE_EQ(a.crossovers[i].ci95.low, b.crossovers[i].ci95.low);
    EXPECT_DOUBLE_EQ(a.crossovers[i].ci95.high, b.crossovers[i].ci95.high);
  }
}

}  // namespace

// Everything conclude() and study.md need comes back: concluded again, the study is written
// out the same, byte for byte.
TEST(StudyJsonRead, RoundTripsEveryFieldConcludeNeeds) {
  StudyResult r = synthetic_study(31);
  r.interrupted = true;
  r.shard = Shard{1, 4};
  r.points[5].busy = true;
  r.points[5].reference_ratio = 1.6;
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
  EXPECT_EQ(back.seed, r.seed);
  EXPECT_EQ(back.bootstrap_replicates, r.bootstrap_replicates);
  EXPECT_EQ(back.command, r.command);
  EXPECT_EQ(back.machine.cpu, r.machine.cpu);
  EXPECT_EQ(back.machine.threads, r.machine.threads);
  EXPECT_EQ(back.machine.kernels, r.machine.kernels);
  EXPECT_EQ(back.machine.versions, r.machine.versions);
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
    EXPECT_EQ(a.seconds, b.seconds);
    EXPECT_EQ(a.order, b.order);
    EXPECT_EQ(a.reference_ratio, b.reference_ratio);
    EXPECT_EQ(a.busy, b.busy);
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
  StudyResult r;
  r.scenes = {"tessphere"};
  r.renderers = {"softraster", "hybrid_soft"};
  r.axes["tessphere"] = "triangles";
  r.width = 1024;
  r.height = 768;
  r.repetitions = 5;
  r.bootstrap_replicates = 50;
  r.mode = "local";
  r.budget_seconds = 10;
  r.seed = 1;
  for (double n : {100.0, 10000.0, 1000000.0})
    for (const std::string& name : r.renderers) {
      Measurement m;
      m.renderer = name;
      m.scene = "tessphere";
      m.scene_n = m.n = n;
      m.width = 1024;
      m.height = 768;
      m.pixels = kP;
      m.seconds = {5e-3, 6e-3, 7e-3, 8e-3, 9e-3};
      m.order = {0, 1, 0, 1, 0};
      if (name == "hybrid_soft") {
        m.phases["zbuffer"] = {1e-3, 3e-3, 2e-3, 5e-3, 4e-3};  // median 3 ms
        m.phases["trace"] = {2e-3, 1e-3, 3e-3, 1e-3, 6e-3};    // median 2 ms
      }
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
  refused([](nlohmann::json& d) { d["format"] = "rvr-study/2"; }, "d/study.json: format: must be");
  refused([](nlohmann::json& d) { d.erase("machine"); }, "d/study.json: machine: is required");
  refused([](nlohmann::json& d) { d["points"][3]["seconds"][1] = -1.0; },
          "d/study.json: points[3].seconds[1]: must be >= 0");
  refused([](nlohmann::json& d) { d["points"][0]["renderer"] = "embree"; },
          "points[0].renderer: string \"embree\" is not in renderer_order");
  refused([](nlohmann::json& d) { d["points"][2]["order"] = {0}; }, "points[2].order:");
  refused([](nlohmann::json& d) { d["width"] = "wide"; }, "width: must be a whole number");
  refused([](nlohmann::json& d) { d["renderer_order"][1] = "nosuch"; }, "renderer_order[1]:");
  refused([](nlohmann::json& d) { d["shard"] = {{"index", 4}, {"count", 4}}; }, "shard.index");
  refused([](nlohmann::json& d) { d["scenes"][0]["axis"] = "depth"; }, "scenes[0].axis");
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
// the same models, intervals and crossovers.
TEST(StudyMerge, TwoHalvesGiveTheModelsOfTheWhole) {
  StudyResult whole = synthetic_study(33);
  conclude(whole, {whole.bootstrap_replicates, whole.seed});
  std::vector<StudySource> halves;
  for (size_t i = 0; i < 2; ++i)
    halves.push_back({"shard-" + std::to_string(i), read_back(shard_of(whole, i, 2))});
  std::swap(halves[0], halves[1]);  // the order given does not matter
  Expected<std::vector<MachineGroup>> merged = merge_studies(halves);
  ASSERT_TRUE(merged.ok()) << merged.error().message;
  ASSERT_EQ(merged->size(), 1u);
  const StudyResult& m = (*merged)[0].study;
  EXPECT_EQ(m.points.size(), whole.points.size());
  EXPECT_FALSE(m.shard.has_value());
  EXPECT_EQ(m.budget_seconds, 2 * whole.budget_seconds);
  ASSERT_EQ(whole.crossovers.size(), 1u);
  expect_same_conclusions(m, whole);
  for (const std::string& note : m.notes) EXPECT_EQ(note.find("missing"), std::string::npos);

  std::vector<StudySource> one_half = {halves[0]};
  Expected<std::vector<MachineGroup>> partial = merge_studies(one_half);
  ASSERT_TRUE(partial.ok());
  bool said = false;
  for (const std::string& note : (*partial)[0].study.notes)
    said = said || note.find("shard 0 of 2 missing") != std::string::npos;
  EXPECT_TRUE(said) << "a missing shard is not noted";
}

TEST(StudyMerge, APointMeasuredTwiceKeepsEveryRepetition) {
  StudyResult r = synthetic_study(34);
  Expected<std::vector<MachineGroup>> merged = merge_studies({{"a", r}, {"b", r}});
  ASSERT_TRUE(merged.ok()) << merged.error().message;
  const StudyResult& m = (*merged)[0].study;
  ASSERT_EQ(m.points.size(), r.points.size());
  for (size_t i = 0; i < r.points.size(); ++i) {
    std::vector<double> both = r.points[i].seconds;
    both.insert(both.end(), r.points[i].seconds.begin(), r.points[i].seconds.end());
    EXPECT_EQ(m.points[i].seconds, both);
    EXPECT_EQ(m.points[i].order.size(), both.size());
  }
  // A point measured on a busy machine by one study and a quiet one by the other: the quiet's.
  StudyResult busy = r;
  busy.points[0].busy = true;
  busy.points[0].seconds = {9, 9, 9, 9, 9};
  for (const auto& order : {std::vector<StudySource>{{"a", r}, {"b", busy}},
                            std::vector<StudySource>{{"b", busy}, {"a", r}}}) {
    Expected<std::vector<MachineGroup>> quiet = merge_studies(order);
    ASSERT_TRUE(quiet.ok());
    EXPECT_EQ((*quiet)[0].study.points[0].seconds, r.points[0].seconds);
    EXPECT_FALSE((*quiet)[0].study.points[0].busy);
  }
  StudyResult moved = r;
  moved.points[0].n += 1;
  Expected<std::vector<MachineGroup>> clash = merge_studies({{"a", r}, {"b", moved}});
  ASSERT_FALSE(clash.ok());
  EXPECT_NE(clash.error().message.find("not the same point"), std::string::npos);
  StudyResult wider = r;
  wider.width = 2048;
  Expected<std::vector<MachineGroup>> sizes = merge_studies({{"a", r}, {"b", wider}});
  ASSERT_FALSE(sizes.ok());
  EXPECT_NE(sizes.error().message.find("one image size"), std::string::npos);
}

// Another machine type (here: other SIMD kernels) or another mode is concluded apart and
// compared side by side.
TEST(StudyMerge, DifferentKernelsAreNotPooled) {
  StudyResult avx2 = synthetic_study(35), avx512 = synthetic_study(36), full = synthetic_study(37);
  avx512.machine.kernels = "avx512 (the widest this CPU runs)";
  full.mode = "full";
  Expected<std::vector<MachineGroup>> merged =
      merge_studies({{"x", avx2}, {"y", avx512}, {"z", full}, {"x2", avx2}});
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
