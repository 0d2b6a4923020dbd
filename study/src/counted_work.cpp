// Work models from the renderers' counters, and the counts' scaling (see counted_work.h).
#include "rvr/study/counted_work.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <type_traits>
#include <utility>

#include "rvr/core/expected.h"
#include "rvr/study/least_squares.h"

namespace rvr::study {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The same wording for a count in each loop order that has it.
constexpr const char* kPixels = "the frame's pixels: cleared, resolved and written out";
constexpr const char* kSubmitted = "triangles transformed, projected and tested against the view";
constexpr const char* kSetup =
    "triangles set up (edge functions, bounding box) and binned to tiles: those left after "
    "culling with a pixel centre in their bounds";
constexpr const char* kClipped = "triangles clipped against the near plane or the guard band";
constexpr const char* kHizBlocks = "8×8 blocks skipped whole by hierarchical z, one test each";
constexpr const char* kGenerated = "pixels whose coverage and depth were tested (fragments)";
constexpr const char* kPassed = "fragments that passed the depth test and were written";
constexpr const char* kShaded = "visible pixels shaded, once each (deferred shading)";
constexpr const char* kShadowShadowRays = "shadow rays traced (any hit: the first one ends them)";
constexpr const char* kReflection = "reflection rays traced";
constexpr const char* kRefraction = "refraction rays traced";
constexpr const char* kNodes = "BVH nodes visited by every ray: child boxes tested";
constexpr const char* kPrimitiveTests = "ray–primitive intersection tests";

}  // namespace

const std::vector<WorkCounter>& work_counters(ModelForm form) {
  static const std::vector<WorkCounter> zbuffer = {
      {"pixels", kPixels},
      {"triangles.submitted", kSubmitted},
      {"triangles.setup", kSetup},
      {"triangles.clipped", kClipped},
      {"hiz.blocks_rejected", kHizBlocks},
      {"fragments.generated", kGenerated},
      {"fragments.passed", kPassed},
      {"fragments.shaded", kShaded},
      {"pixels.covered", "pixels a surface covers at the end (what is seen)"},
      {"shadows.triangles_setup", "triangles set up for the lights' shadow cube maps"},
      {"shadows.fragments", "fragments tested in the lights' shadow cube maps"},
      {"shadow_map.texels", "texels drawn into the lights' shadow maps"},
  };
  static const std::vector<WorkCounter> tracer = {
      {"rays.primary", "camera rays: made, traced, and their hit or the background shaded"},
      {"rays.shadow", kShadowShadowRays},
      {"rays.reflection", kReflection},
      {"rays.refraction", kRefraction},
      {"bvh.nodes_visited", kNodes},
      {"primitive_tests", kPrimitiveTests},
      {"pixels", kPixels},
  };
  static const std::vector<WorkCounter> hybrid = {
      {"pixels", kPixels},
      {"zbuffer.triangles.submitted", kSubmitted},
      {"zbuffer.triangles.setup", kSetup},
      {"zbuffer.hiz.blocks_rejected", kHizBlocks},
      {"zbuffer.fragments.generated", kGenerated},
      {"zbuffer.fragments.passed", kPassed},
      {"hybrid.rebuilt", "pixels whose primary hit is rebuilt from the z-buffer's ids, no ray"},
      {"hybrid.fallback_traced", "pixels the z-buffer could not settle, traced as primary rays"},
      {"rays.shadow", kShadowShadowRays},
      {"rays.reflection", kReflection},
      {"rays.refraction", kRefraction},
      {"bvh.nodes_visited", kNodes},
      {"primitive_tests", kPrimitiveTests},
  };
  switch (form) {
    case ModelForm::ZBuffer:
      return zbuffer;
    case ModelForm::Tracer:
      return tracer;
    case ModelForm::Hybrid:
      return hybrid;
  }
  return zbuffer;
}

double count_of(const Measurement& m, const std::string& counter) {
  if (counter == "pixels") return m.pixels;
  auto it = m.counters.find(counter);
  return it == m.counters.end() ? kNaN : it->second;
}

namespace {

// The weighted R² of `v` fitted on the columns kept (the constant among them), and the kept
// column it correlates with most (weighted): how well the counts kept already explain it.
struct Explained {
  double r2 = 0;
  size_t closest = 0;
};

Explained explained(const std::vector<std::vector<double>>& kept, const std::vector<double>& v,
                    const std::vector<double>& w) {
  Explained out;
  const size_t n = v.size();
  double sw = 0, mean = 0;
  for (size_t i = 0; i < n; ++i) sw += w[i], mean += w[i] * v[i];
  mean /= sw;
  double total = 0;
  for (size_t i = 0; i < n; ++i) total += w[i] * (v[i] - mean) * (v[i] - mean);
  std::vector<std::vector<double>> x(n);
  for (size_t i = 0; i < n; ++i)
    for (const std::vector<double>& column : kept) x[i].push_back(column[i]);
  Expected<std::vector<double>> beta =
      weighted_least_squares(x, v, w, std::vector<bool>(kept.size(), true));
  if (!beta || !(total > 0)) {
    out.r2 = 1;
    return out;
  }
  double residual = 0;
  for (size_t i = 0; i < n; ++i) {
    double fitted = 0;
    for (size_t j = 0; j < kept.size(); ++j) fitted += x[i][j] * (*beta)[j];
    residual += w[i] * (v[i] - fitted) * (v[i] - fitted);
  }
  out.r2 = 1 - residual / total;
  double best = -1;
  for (size_t j = 1; j < kept.size(); ++j) {  // column 0 is the constant
    double mk = 0;
    for (size_t i = 0; i < n; ++i) mk += w[i] * kept[j][i];
    mk /= sw;
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < n; ++i) {
      sxy += w[i] * (kept[j][i] - mk) * (v[i] - mean);
      sxx += w[i] * (kept[j][i] - mk) * (kept[j][i] - mk);
    }
    const double c = sxx > 0 ? std::fabs(sxy) / std::sqrt(sxx * total) : 0;
    if (c > best) best = c, out.closest = j;
  }
  return out;
}

// The least-squares line y = intercept + slope·x, and its R².
struct Line {
  double intercept = kNaN, slope = kNaN, r2 = kNaN;
};

Line fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  Line l;
  const double n = double(x.size());
  if (x.size() < 2) return l;
  double sx = 0, sy = 0;
  for (size_t i = 0; i < x.size(); ++i) sx += x[i], sy += y[i];
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0, syy = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (!(sxx > 0)) return l;
  l.slope = sxy / sxx;
  l.intercept = my - l.slope * mx;
  l.r2 = syy > 0 ? sxy * sxy / (sxx * syy) : 1.0;
  return l;
}

// The points at `pixels`, in increasing N, one per N.
std::vector<const Measurement*> along_n(const std::vector<Measurement>& points, double pixels) {
  std::map<double, const Measurement*> by_n;
  for (const Measurement& m : points)
    if (m.pixels == pixels) by_n.emplace(m.n, &m);
  std::vector<const Measurement*> out;
  out.reserve(by_n.size());
  for (const auto& [n, m] : by_n) out.push_back(m);
  return out;
}

// Every count of a loop order but the pixel count itself (its scaling is known).
std::vector<std::string> scaled_counts(ModelForm form) {
  std::vector<std::string> out;
  for (const WorkCounter& c : work_counters(form))
    if (std::string(c.name) != "pixels") out.push_back(c.name);
  return out;
}

// The log-log line of `counter` against the axis (N, or the pixel count) over `points`, those
// with a positive count.
std::optional<CountScaling> scaling_of(const std::vector<const Measurement*>& points,
                                       const std::string& counter, bool pixels_axis) {
  std::vector<double> x, y;
  CountScaling s;
  s.from = std::numeric_limits<double>::infinity();
  s.to = 0;
  for (const Measurement* m : points) {
    const double v = count_of(*m, counter), at = pixels_axis ? m->pixels : m->n;
    if (!(v > 0) || !(at > 0)) continue;
    x.push_back(std::log(at));
    y.push_back(std::log(v));
    s.from = std::min(s.from, at);
    s.to = std::max(s.to, at);
  }
  const Line line = fit_line(x, y);
  if (!std::isfinite(line.slope)) return std::nullopt;
  s.counter = counter;
  s.exponent = line.slope;
  s.r2 = line.r2;
  s.points = x.size();
  return s;
}

// The line of value(m) against x_of(N) over the points where the value is positive, and the
// value's log-log slope against N: the numbers of a CountClaim.
std::optional<CountClaim> line_claim(const std::vector<const Measurement*>& line,
                                     const std::function<double(const Measurement&)>& value,
                                     const std::function<double(double)>& x_of) {
  std::vector<double> x, y, log_n, log_y;
  CountClaim c;
  c.from = std::numeric_limits<double>::infinity();
  for (const Measurement* m : line) {
    const double v = value(*m);
    if (!(v > 0) || !std::isfinite(v) || !(m->n > 0)) continue;
    x.push_back(x_of(m->n));
    y.push_back(v);
    log_n.push_back(std::log(m->n));
    log_y.push_back(std::log(v));
    c.from = std::min(c.from, m->n);
    c.to = std::max(c.to, m->n);
  }
  const Line fitted = fit_line(x, y);
  if (!std::isfinite(fitted.slope)) return std::nullopt;
  c.intercept = fitted.intercept;
  c.slope = fitted.slope;
  c.r2 = fitted.r2;
  c.exponent = fit_line(log_n, log_y).slope;
  c.points = x.size();
  return c;
}

}  // namespace

WorkModel fit_work_model(const std::string& renderer, ModelForm form,
                         const std::vector<Measurement>& points, const BootstrapOptions& boot,
                         const FitThresholds& limits) {
  WorkModel model;
  model.renderer = renderer;
  model.scene = points.empty() ? "" : points[0].scene;
  model.points = points.size();
  const size_t n = points.size();
  std::vector<double> w;
  for (const Measurement& p : points) {
    const double t = typical_seconds(p);
    w.push_back(t > 0 ? 1.0 / (t * t) : 0.0);
  }
  std::vector<std::vector<double>> kept = {std::vector<double>(n, 1.0)};
  std::vector<std::string> names = {"frame"};
  model.counts = {"every frame, whatever its work"};
  for (const WorkCounter& c : work_counters(form)) {
    std::vector<double> v;
    size_t missing = 0;
    for (const Measurement& p : points) {
      v.push_back(count_of(p, c.name));
      missing += !std::isfinite(v.back());
    }
    if (missing == n) continue;  // the renderer does not count it: nothing to say
    if (missing > 0) {
      model.left_out.push_back({c.name, fmt::format("not counted at {} of {} points", missing, n)});
      continue;
    }
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    if (*lo == *hi) {
      model.left_out.push_back({c.name, *lo == 0 ? "zero at every point"
                                                 : fmt::format("{} at every point: part of the "
                                                               "frame's constant",
                                                               *lo)});
      continue;
    }
    const size_t nonzero =
        size_t(std::count_if(v.begin(), v.end(), [](double x) { return x != 0; }));
    if (nonzero < kMinCountedPoints) {
      model.left_out.push_back(
          {c.name,
           fmt::format("non-zero at {} of {} points: too few to tell its cost", nonzero, n)});
      continue;
    }
    const Explained e = explained(kept, v, w);
    if (e.r2 >= kCollinearR2) {
      model.left_out.push_back(
          {c.name, fmt::format("follows {}: R² {:.4f} on the counts kept before it, so its cost "
                               "is in theirs",
                               names[e.closest], e.r2)});
      continue;
    }
    if (n < kept.size() + 3) {
      model.left_out.push_back(
          {c.name, fmt::format("{} points leave no room for another term", n)});
      continue;
    }
    kept.push_back(v);
    names.push_back(c.name);
    model.counts.push_back(c.counts);
  }
  model.terms.resize(kept.size());
  for (size_t j = 0; j < kept.size(); ++j) model.terms[j].name = names[j];
  if (n < kept.size() + 2) {
    model.verdict = fmt::format("does not fit: {} points for {} terms (at least {} needed)", n,
                                kept.size(), kept.size() + 2);
    return model;
  }
  std::vector<std::vector<double>> rows(n, std::vector<double>(kept.size()));
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < kept.size(); ++j) rows[i][j] = kept[j][i];
  Expected<LinearFit> fit = fit_linear(rows, points, std::vector<bool>(kept.size(), true), boot);
  if (!fit) {
    model.verdict = "does not fit: " + fit.error().message;
    return model;
  }
  for (size_t j = 0; j < kept.size(); ++j) {
    model.terms[j].value = fit->values[j];
    model.terms[j].ci95 = fit->ci95[j];
  }
  take_fit(model, *fit, limits);
  return model;
}

double predict_work_seconds(const WorkModel& model, const Measurement& point) {
  if (model.terms.empty()) return kNaN;
  double t = model.terms[0].value;
  for (size_t j = 1; j < model.terms.size(); ++j)
    t += model.terms[j].value * count_of(point, model.terms[j].name);
  return t;
}

std::vector<CountScaling> count_scaling(const std::string& renderer, ModelForm form,
                                        const std::string& scene, const std::string& axis,
                                        double full_pixels,
                                        const std::vector<Measurement>& points) {
  std::vector<CountScaling> out;
  auto add = [&](std::optional<CountScaling> s, const std::string& on, double n) {
    if (!s) return;
    s->renderer = renderer;
    s->scene = scene;
    s->axis = on;
    s->n = n;
    out.push_back(*s);
  };
  // The pixel sweep's columns: the N measured at more than one pixel count.
  std::map<double, std::map<double, const Measurement*>> columns;
  for (const Measurement& m : points) columns[m.scene_n].emplace(m.pixels, &m);
  for (const std::string& counter : scaled_counts(form)) {
    add(scaling_of(along_n(points, full_pixels), counter, false), axis, 0);
    for (const auto& [scene_n, by_pixels] : columns) {
      if (by_pixels.size() < 2) continue;
      std::vector<const Measurement*> column;
      for (const auto& [p, m] : by_pixels) column.push_back(m);
      add(scaling_of(column, counter, true), "pixels", column[0]->n);
    }
  }
  return out;
}

std::vector<CountClaim> count_claims(const std::string& renderer, ModelForm form,
                                     const std::string& scene, const std::string& axis,
                                     double full_pixels, const std::vector<Measurement>& points) {
  const std::vector<const Measurement*> line = along_n(points, full_pixels);
  std::vector<CountClaim> out;
  if (line.empty()) return out;
  auto counted = [](const Measurement& m, const std::string& name) {
    const double v = count_of(m, name);
    return std::isfinite(v) ? v : 0.0;
  };
  auto has = [&](const std::string& name) { return std::isfinite(count_of(*line[0], name)); };
  auto add = [&](std::optional<CountClaim> c, std::string claim, std::string quantity,
                 std::string against) {
    if (!c) return;
    c->renderer = renderer;
    c->scene = scene;
    c->claim = std::move(claim);
    c->quantity = std::move(quantity);
    c->against = std::move(against);
    out.push_back(std::move(*c));
  };
  if (form == ModelForm::Tracer && axis == "triangles" && has("bvh.nodes_visited")) {
    add(line_claim(
            line,
            [&](const Measurement& m) {
              const double rays = counted(m, "rays.primary") + counted(m, "rays.shadow") +
                                  counted(m, "rays.reflection") + counted(m, "rays.refraction");
              return counted(m, "bvh.nodes_visited") / rays;
            },
            [](double n) { return std::log2(n); }),
        "nodes_per_ray", "bvh.nodes_visited / rays", "log2 N");
  }
  const std::string prefix = form == ModelForm::Hybrid ? "zbuffer." : "";
  const std::string fragments = prefix + "fragments.generated";
  if (form != ModelForm::Tracer && axis == "depth" && has(fragments)) {
    add(line_claim(
            line, [&](const Measurement& m) { return counted(m, fragments) / m.pixels; },
            [](double n) { return n; }),
        "fragments_per_pixel", fragments + " / pixels", "D");
  }
  std::string setup = prefix + "triangles.setup";
  if (!has(setup)) setup = prefix + "triangles.submitted";
  if (form != ModelForm::Tracer && axis == "triangles" && has(setup)) {
    add(line_claim(
            line, [&](const Measurement& m) { return counted(m, setup); },
            [](double n) { return n; }),
        "triangles_set_up", setup, "N");
  }
  return out;
}

}  // namespace rvr::study
