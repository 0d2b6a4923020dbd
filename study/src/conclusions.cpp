// Conclusions from the measurements (see conclusions.h).
#include "rvr/study/conclusions.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <type_traits>
#include <utility>

#include "rvr/core/expected.h"
#include "rvr/renderers/registry.h"
#include "rvr/study/counted_work.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/scene_changes.h"
#include "rvr/study/study_markdown.h"

namespace rvr::study {
namespace {

// In every note conclude() adds: a pair tied within the noise, a comparison with too few points,
// a model fitted to busy times.
constexpr const char* kTieWords = "are within the noise threshold of each other";
constexpr const char* kFewWords = "nothing is concluded along";
constexpr const char* kBusyFitWords = "fitted to times measured while the machine was busy";
constexpr const char* kNoConclusionWords = "the study concludes nothing";

std::vector<Measurement> points_of(const StudyResult& r, const std::string& renderer,
                                   const std::string& scene) {
  std::vector<Measurement> out;
  for (const Measurement& m : r.points)
    if (m.renderer == renderer && m.scene == scene && !m.runs.empty()) out.push_back(m);
  return out;
}

// The points a renderer's model is fitted to: those with a quiet run, unless too few have one
// (then all, and a note says the absolute times are a busy machine's).
std::vector<Measurement> fit_points(StudyResult& r, const std::string& renderer,
                                    const std::string& scene, size_t enough) {
  std::vector<Measurement> all = points_of(r, renderer, scene), quiet;
  for (const Measurement& m : all)
    if (!m.busy()) quiet.push_back(m);
  if (quiet.size() >= enough || quiet.size() == all.size()) return quiet;
  r.notes.push_back(
      fmt::format("{} on {}: {} (only {} of {} points had a quiet run): its costs are overstated",
                  renderer, scene, kBusyFitWords, quiet.size(), all.size()));
  return all;
}

// The points along the family's axis: those at the study's full image size.
std::vector<Measurement> along_n(const StudyResult& r, const std::string& renderer,
                                 const std::string& scene) {
  std::vector<Measurement> out;
  for (const Measurement& m : points_of(r, renderer, scene))
    if (m.pixels == double(r.width) * double(r.height)) out.push_back(m);
  return out;
}

// The points of the pixel sweep at one N (all its widths, the full one included).
std::vector<Measurement> along_pixels(const StudyResult& r, const std::string& renderer,
                                      const std::string& scene, double scene_n) {
  std::vector<Measurement> out;
  for (const Measurement& m : points_of(r, renderer, scene))
    if (m.scene_n == scene_n) out.push_back(m);
  return out;
}

// The N of a scene at which more than one width was measured, in increasing order.
std::vector<double> pixel_sweep_columns(const StudyResult& r, const std::string& scene) {
  std::map<double, std::set<double>> widths;
  for (const Measurement& m : r.points)
    if (m.scene == scene && !m.runs.empty()) widths[m.scene_n].insert(m.pixels);
  std::vector<double> out;
  for (const auto& [n, w] : widths)
    if (w.size() > 1) out.push_back(n);
  return out;
}

// The textbook form of a loop order for a family's axis: with the fragments' P·D term where the
// axis is depth complexity.
CostModel textbook_model(ModelForm form, const std::string& axis) {
  CostModel m(form);
  m.depth = axis == "depth";
  return m;
}

LoopOrder order_of(const std::string& renderer) {
  Expected<RendererChoice> c = find_renderer_choice(renderer);
  return c ? c->info->order : LoopOrder::TriangleMajor;
}

// The renderer's work model of a family from the points its formula model is fitted to (none
// when they carry no counts), and its counts' scaling and the chapter's claims from every point
// it measured (counts do not depend on how busy the machine was).
void counted_work(StudyResult& r, const std::string& renderer, ModelForm form,
                  const std::string& scene, const std::vector<Measurement>& fitted,
                  const BootstrapOptions& boot) {
  const bool counted = std::any_of(fitted.begin(), fitted.end(),
                                   [](const Measurement& m) { return !m.counters.empty(); });
  if (counted) r.work_models.push_back(fit_work_model(renderer, form, fitted, boot));
  const std::vector<Measurement> all = points_of(r, renderer, scene);
  const double full = double(r.width) * double(r.height);
  for (CountScaling& s : count_scaling(renderer, form, scene, r.axes[scene], full, all))
    r.count_scaling.push_back(std::move(s));
  for (CountClaim& c : count_claims(renderer, form, scene, r.axes[scene], full, all))
    r.count_claims.push_back(std::move(c));
}

void fit_models(StudyResult& r, const BootstrapOptions& boot) {
  for (const std::string& name : r.renderers) {
    RendererModels m;
    m.name = name;
    m.loop_order = short_name(order_of(name));
    m.form = model_form_of(name);
    for (const std::string& scene : r.scenes) {
      const CostModel textbook = textbook_model(m.form, r.axes[scene]);
      const size_t enough = coefficient_names(textbook).size() + 2;
      const std::vector<Measurement> points = fit_points(r, name, scene, enough);
      m.fits[scene] = fit_chosen_model(textbook, points, boot);
      counted_work(r, name, m.form, scene, points, boot);
    }
    r.models.push_back(m);
  }
}

const ModelFit& fit_of(const StudyResult& r, const std::string& renderer,
                       const std::string& scene) {
  for (const RendererModels& m : r.models)
    if (m.name == renderer) return m.fits.at(scene);
  static const ModelFit none;
  return none;
}

// A dominance whose models cross outside the swept range adds that crossover, not measured.
void add_extrapolated(StudyResult& r, const Dominance& d) {
  const ModelFit &fa = fit_of(r, d.faster, d.scene), &fb = fit_of(r, d.slower, d.scene);
  std::optional<double> x = extrapolated_crossing(fa, fb, d.pixels, d.range_low, d.range_high);
  if (!x) return;
  Crossover c;
  c.a = d.faster;
  c.b = d.slower;
  c.scene = d.scene;
  c.axis = d.axis;
  c.value = *x;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.ci95 = {nan, nan};
  c.pixels = d.pixels;
  c.a_faster_below = *x > d.range_high;  // the faster one stops winning above the range
  c.measured = false;
  c.range_low = d.range_low;
  c.range_high = d.range_high;
  r.crossovers.push_back(c);
}

// The notes of a comparison that concludes nothing: tied, or too few points.
void comparison_notes(StudyResult& r, const CurveComparison& c) {
  const Comparison& x = c.comparison;
  const std::string along =
      x.axis == kPixelsAxis
          ? fmt::format("the pixel count at {} {}", format_number(x.n), r.axes[x.scene])
          : fmt::format("{} at {}×{}", x.axis, r.width, r.height);
  if (!x.inconclusive.empty())
    r.notes.push_back(fmt::format("{}: for {} and {}, {} {}: {}", x.scene, x.a, x.b, kFewWords,
                                  along, x.inconclusive));
  else if (c.tie)
    r.notes.push_back(fmt::format("{}: {} and {} {} ({:.0f}%) along {}, at every point measured",
                                  x.scene, x.a, x.b, kTieWords, 100 * r.noise_threshold, along));
}

void add_comparison(StudyResult& r, const CurveComparison& c, bool extrapolate) {
  if (c.comparison.points.empty()) return;
  r.comparisons.push_back(c.comparison);
  for (const Crossover& x : c.crossovers) r.crossovers.push_back(x);
  if (c.dominance) {
    r.dominance.push_back(*c.dominance);
    if (extrapolate) add_extrapolated(r, *c.dominance);
  }
  comparison_notes(r, c);
}

// Every pair the study compares, along N at the full width and along the pixel count at each N
// of the pixel sweep.
void compare_pairs(StudyResult& r, const BootstrapOptions& boot) {
  const CompareOptions options{boot, r.noise_threshold};
  for (const std::string& scene : r.scenes)
    for (size_t i = 0; i < r.renderers.size(); ++i)
      for (size_t j = i + 1; j < r.renderers.size(); ++j) {
        const std::string &a = r.renderers[i], &b = r.renderers[j];
        if (!compared_pair(a, b)) continue;
        add_comparison(
            r, compare_curves(along_n(r, a, scene), along_n(r, b, scene), r.axes[scene], options),
            true);
        for (double n : pixel_sweep_columns(r, scene))
          add_comparison(r,
                         compare_curves(along_pixels(r, a, scene, n), along_pixels(r, b, scene, n),
                                        kPixelsAxis, options),
                         false);
      }
}

// The slope along N over every decade [10^k, 10^(k+1)] the full-width points span, and along
// the pixel count over each pixel sweep.
void scaling(StudyResult& r) {
  for (const std::string& name : r.renderers)
    for (const std::string& scene : r.scenes) {
      const std::string& axis = r.axes[scene];
      std::vector<Measurement> p = along_n(r, name, scene);
      if (p.empty()) continue;
      double lo = p[0].n, hi = p[0].n;
      for (const Measurement& m : p) lo = std::min(lo, m.n), hi = std::max(hi, m.n);
      for (double from = std::pow(10.0, std::floor(std::log10(lo))); from < hi; from *= 10) {
        double slope = loglog_slope(p, from, from * 10, axis);
        if (std::isfinite(slope))
          r.scaling.push_back({name, scene, axis, from, from * 10, slope, 0});
      }
      for (double n : pixel_sweep_columns(r, scene)) {
        std::vector<Measurement> column = along_pixels(r, name, scene, n);
        double from = column[0].pixels, to = column[0].pixels;
        for (const Measurement& m : column)
          from = std::min(from, m.pixels), to = std::max(to, m.pixels);
        double slope = loglog_slope(column, from, to, kPixelsAxis);
        if (std::isfinite(slope))
          r.scaling.push_back({name, scene, kPixelsAxis, from, to, slope, column[0].n});
      }
    }
}

// At the smallest and the largest n of each renderer and scene.
void unit_costs(StudyResult& r) {
  for (const std::string& name : r.renderers)
    for (const std::string& scene : r.scenes) {
      std::vector<Measurement> p = along_n(r, name, scene);
      if (p.empty()) continue;
      const Measurement *lo = &p[0], *hi = &p[0];
      for (const Measurement& m : p) {
        if (m.n < lo->n) lo = &m;
        if (m.n > hi->n) hi = &m;
      }
      for (const Measurement* m : {lo, hi}) {
        double t = typical_seconds(*m);
        r.costs.push_back({name, scene, m->n, t, 1e9 * t / m->n, 1e9 * t / m->pixels});
        if (lo == hi) break;
      }
    }
}

}  // namespace

// Whether the study compares two renderers: of different loop orders, or one renderer and its
// variant (softraster and softraster_nohiz: what hierarchical z saves; raytrace and
// raytrace_bvh2).
bool compared_pair(const std::string& a, const std::string& b) {
  Expected<RendererChoice> ca = find_renderer_choice(a), cb = find_renderer_choice(b);
  if (!ca || !cb) return false;
  return ca->info->order != cb->info->order || ca->info == cb->info;
}

ModelForm model_form_of(const std::string& renderer) {
  switch (order_of(renderer)) {
    case LoopOrder::TriangleMajor:
      return ModelForm::ZBuffer;
    case LoopOrder::PixelMajor:
      return ModelForm::Tracer;
    case LoopOrder::Hybrid:
      return ModelForm::Hybrid;
  }
  return ModelForm::ZBuffer;
}

double loglog_slope(const std::vector<Measurement>& points, double from, double to,
                    const std::string& axis) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const Measurement& m : points) {
    const double v = axis == kPixelsAxis ? m.pixels : m.n;
    if (v < from * (1 - 1e-9) || v > to * (1 + 1e-9)) continue;
    double x = std::log10(v), y = std::log10(typical_seconds(m));
    n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  double denominator = n * sxx - sx * sx;
  if (n < 2 || denominator <= 1e-12) return std::numeric_limits<double>::quiet_NaN();
  return (n * sxy - sx * sy) / denominator;
}

bool is_conclusion_note(const std::string& note) {
  for (const char* words : {kTieWords, kFewWords, kBusyFitWords, kNoConclusionWords})
    if (note.find(words) != std::string::npos) return true;
  return false;
}

namespace {

// Every repetition's seconds of one phase, over the point's timed runs.
std::vector<double> phase_seconds(const Measurement& m, const std::string& phase) {
  std::vector<double> out;
  for (const Run* run : timed_runs(m))
    if (auto it = run->phases.find(phase); it != run->phases.end())
      out.insert(out.end(), it->second.begin(), it->second.end());
  return out;
}

// The hybrids' z-buffer/trace split at the smallest and largest N at full width.
void phase_splits(StudyResult& r) {
  for (const std::string& name : r.renderers)
    for (const std::string& scene : r.scenes) {
      std::vector<Measurement> p = along_n(r, name, scene);
      std::erase_if(p, [](const Measurement& m) {
        return phase_seconds(m, "zbuffer").empty() || phase_seconds(m, "trace").empty();
      });
      if (p.empty()) continue;
      auto by_n = [](const Measurement& x, const Measurement& y) { return x.n < y.n; };
      for (const Measurement* m : {&*std::min_element(p.begin(), p.end(), by_n),
                                   &*std::max_element(p.begin(), p.end(), by_n)}) {
        const double z = median(phase_seconds(*m, "zbuffer")),
                     t = median(phase_seconds(*m, "trace"));
        r.splits.push_back({name, scene, m->n, m->pixels, z, t, z + t > 0 ? z / (z + t) : 0});
        if (p.size() == 1) break;
      }
    }
}

// Why nothing is concluded, when nothing is: no comparison found a crossover, a dominance or a
// tie, and no model fits.
std::string no_conclusion_reason(const StudyResult& r) {
  if (!r.crossovers.empty() || !r.dominance.empty()) return "";
  for (const RendererModels& m : r.models)
    for (const auto& [scene, f] : m.fits)
      if (f.fits) return "";
  size_t ties = 0;
  for (const std::string& note : r.notes) ties += note.find(kTieWords) != std::string::npos;
  if (ties > 0) return "";
  size_t points = 0, busy = 0;
  for (const Measurement& m : r.points) points += 1, busy += m.busy();
  if (points == 0)
    return "no point was measured: the budget or an interruption stopped the sweep before its "
           "first point";
  std::string why = fmt::format(
      "{} measurements at {} points, too few for a comparison ({} points along an axis) or "
      "a model",
      points, points / std::max<size_t>(r.renderers.size(), 1), kMinComparedPoints);
  if (busy > 0) why += fmt::format("; {} of them measured only while the machine was busy", busy);
  return why + ": give the study a larger --budget";
}

}  // namespace

void conclude(StudyResult& result, const BootstrapOptions& boot) {
  fit_models(result, boot);
  compare_pairs(result, boot);
  scaling(result);
  unit_costs(result);
  phase_splits(result);
  scene_change_conclusions(result, boot);
  result.no_conclusion = no_conclusion_reason(result);
  if (!result.no_conclusion.empty())
    result.notes.push_back(std::string(kNoConclusionWords) + ": " + result.no_conclusion);
}

}  // namespace rvr::study
