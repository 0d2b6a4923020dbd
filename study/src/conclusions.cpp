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

#include "rvr/renderers/registry.h"
#include "rvr/shared/expected.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/study_markdown.h"

namespace rvr::study {
namespace {

// In every note conclude() adds: a pair tied within the noise.
constexpr const char* kTieWords = "are within the timing noise of each other";

std::vector<Measurement> points_of(const StudyResult& r, const std::string& renderer,
                                   const std::string& scene) {
  std::vector<Measurement> out;
  for (const Measurement& m : r.points)
    if (m.renderer == renderer && m.scene == scene && !m.busy) out.push_back(m);
  return out;
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
    if (m.scene == scene && !m.busy) widths[m.scene_n].insert(m.pixels);
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

void fit_models(StudyResult& r, const BootstrapOptions& boot) {
  for (const std::string& name : r.renderers) {
    RendererModels m;
    m.name = name;
    m.loop_order = short_name(order_of(name));
    m.form = model_form_of(name);
    for (const std::string& scene : r.scenes)
      m.fits[scene] =
          fit_chosen_model(textbook_model(m.form, r.axes[scene]), points_of(r, name, scene), boot);
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

// Every pair the study compares, along N at the full width and along the pixel count at each N
// of the pixel sweep.
void compare_pairs(StudyResult& r, const BootstrapOptions& boot) {
  for (const std::string& scene : r.scenes)
    for (size_t i = 0; i < r.renderers.size(); ++i)
      for (size_t j = i + 1; j < r.renderers.size(); ++j) {
        const std::string &a = r.renderers[i], &b = r.renderers[j];
        if (!compared_pair(a, b)) continue;
        CurveComparison c =
            compare_curves(along_n(r, a, scene), along_n(r, b, scene), r.axes[scene], boot);
        for (const Crossover& x : c.crossovers) r.crossovers.push_back(x);
        if (c.dominance) {
          r.dominance.push_back(*c.dominance);
          add_extrapolated(r, *c.dominance);
        }
        if (c.tie)
          r.notes.push_back(fmt::format("{}: {} and {} {} at every {} measured", scene, a, b,
                                        kTieWords, r.axes[scene]));
        for (double n : pixel_sweep_columns(r, scene)) {
          CurveComparison p = compare_curves(along_pixels(r, a, scene, n),
                                             along_pixels(r, b, scene, n), kPixelsAxis, boot);
          for (const Crossover& x : p.crossovers) r.crossovers.push_back(x);
          if (p.dominance) r.dominance.push_back(*p.dominance);
          if (p.tie)
            r.notes.push_back(fmt::format(
                "{} with {} {}: {} and {} {} at every pixel count measured", scene,
                format_number(along_pixels(r, a, scene, n)[0].n), r.axes[scene], a, b, kTieWords));
        }
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
  return note.find(kTieWords) != std::string::npos;
}

namespace {

// The hybrids' z-buffer/trace split at the smallest and largest N at full width.
void phase_splits(StudyResult& r) {
  for (const std::string& name : r.renderers)
    for (const std::string& scene : r.scenes) {
      std::vector<Measurement> p = along_n(r, name, scene);
      std::erase_if(p, [](const Measurement& m) {
        return !m.phases.count("zbuffer") || !m.phases.count("trace");
      });
      if (p.empty()) continue;
      auto by_n = [](const Measurement& x, const Measurement& y) { return x.n < y.n; };
      for (const Measurement* m : {&*std::min_element(p.begin(), p.end(), by_n),
                                   &*std::max_element(p.begin(), p.end(), by_n)}) {
        const double z = median(m->phases.at("zbuffer")), t = median(m->phases.at("trace"));
        r.splits.push_back({name, scene, m->n, m->pixels, z, t, z + t > 0 ? z / (z + t) : 0});
        if (p.size() == 1) break;
      }
    }
}

}  // namespace

void conclude(StudyResult& result, const BootstrapOptions& boot) {
  fit_models(result, boot);
  compare_pairs(result, boot);
  scaling(result);
  unit_costs(result);
  phase_splits(result);
}

}  // namespace rvr::study
