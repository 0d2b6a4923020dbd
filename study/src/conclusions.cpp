// Conclusions from the measurements (see conclusions.h).
#include "rvr/study/conclusions.h"

#include <cmath>
#include <limits>

#include "rvr/renderers/registry.h"

namespace rvr::study {
namespace {

std::vector<Measurement> points_of(const StudyResult& r, const std::string& renderer,
                                   const std::string& scene) {
  std::vector<Measurement> out;
  for (const Measurement& m : r.points)
    if (m.renderer == renderer && m.scene == scene) out.push_back(m);
  return out;
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
      m.fits[scene] = fit_model(m.form, points_of(r, name, scene), boot);
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

void compare_pairs(StudyResult& r, const BootstrapOptions& boot) {
  for (const std::string& scene : r.scenes)
    for (size_t i = 0; i < r.renderers.size(); ++i)
      for (size_t j = i + 1; j < r.renderers.size(); ++j) {
        const std::string &a = r.renderers[i], &b = r.renderers[j];
        if (order_of(a) == order_of(b)) continue;
        CurveComparison c =
            compare_curves(points_of(r, a, scene), points_of(r, b, scene), r.axes[scene], boot);
        for (const Crossover& x : c.crossovers) r.crossovers.push_back(x);
        if (c.dominance) {
          r.dominance.push_back(*c.dominance);
          add_extrapolated(r, *c.dominance);
        }
      }
}

// The slope over every decade [10^k, 10^(k+1)] the points span.
void scaling(StudyResult& r) {
  for (const std::string& name : r.renderers)
    for (const std::string& scene : r.scenes) {
      std::vector<Measurement> p = points_of(r, name, scene);
      if (p.empty()) continue;
      double lo = p[0].n, hi = p[0].n;
      for (const Measurement& m : p) lo = std::min(lo, m.n), hi = std::max(hi, m.n);
      for (double from = std::pow(10.0, std::floor(std::log10(lo))); from < hi; from *= 10) {
        double slope = loglog_slope(p, from, from * 10);
        if (std::isfinite(slope)) r.scaling.push_back({name, scene, from, from * 10, slope});
      }
    }
}

// At the smallest and the largest n of each renderer and scene.
void unit_costs(StudyResult& r) {
  for (const std::string& name : r.renderers)
    for (const std::string& scene : r.scenes) {
      std::vector<Measurement> p = points_of(r, name, scene);
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

double loglog_slope(const std::vector<Measurement>& points, double from, double to) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const Measurement& m : points) {
    if (m.n < from * (1 - 1e-9) || m.n > to * (1 + 1e-9)) continue;
    double x = std::log10(m.n), y = std::log10(typical_seconds(m));
    n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  double denominator = n * sxx - sx * sx;
  if (n < 2 || denominator <= 1e-12) return std::numeric_limits<double>::quiet_NaN();
  return (n * sxy - sx * sy) / denominator;
}

void conclude(StudyResult& result, const BootstrapOptions& boot) {
  fit_models(result, boot);
  compare_pairs(result, boot);
  scaling(result);
  unit_costs(result);
}

}  // namespace rvr::study
