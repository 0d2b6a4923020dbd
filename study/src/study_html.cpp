// study.html (see study_html.h).
#include "rvr/study/study_html.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <map>
#include <set>
#include <type_traits>
#include <utility>
#include <vector>

#include "counted_work_text.h"
#include "loglog_chart.h"
#include "rvr/present/html_escape.h"
#include "rvr/present/legend.h"
#include "rvr/present/page.h"
#include "rvr/present/powers_of_ten.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"
#include "rvr/study/memory_estimate.h"
#include "rvr/study/study_markdown.h"
#include "rvr/study/system_probe.h"
#include "scene_changes_html.h"

namespace rvr::study {
namespace {

using present::escape_html;
using present::html_with_powers;

// Renderer colours, distinguishable for common colour-blindness (Okabe–Ito, then more).
constexpr const char* kPalette[] = {"#0072b2", "#d55e00", "#009e73", "#cc79a7",
                                    "#e69f00", "#56b4e9", "#7a5c00", "#000000"};

using Colours = std::map<std::string, std::string>;

bool same_value(double a, double b) {
  return std::fabs(a - b) <= 1e-9 * std::max(std::fabs(a), std::fabs(b));
}

// Every renderer, in the order asked for, then any that only the points name.
std::vector<std::string> renderer_names(const StudyResult& r) {
  std::vector<std::string> names = r.renderers;
  for (const Measurement& m : r.points)
    if (std::find(names.begin(), names.end(), m.renderer) == names.end())
      names.push_back(m.renderer);
  return names;
}

// One colour per renderer, the same in every chart and table.
Colours renderer_colours(const StudyResult& r) {
  Colours c;
  const std::vector<std::string> names = renderer_names(r);
  const size_t size = std::size(kPalette);
  for (size_t i = 0; i < names.size(); ++i) c[names[i]] = kPalette[i % size];
  return c;
}

const ModelFit* fit_of(const StudyResult& r, const std::string& renderer,
                       const std::string& scene) {
  for (const RendererModels& m : r.models) {
    if (m.name != renderer) continue;
    auto it = m.fits.find(scene);
    return it == m.fits.end() ? nullptr : &it->second;
  }
  return nullptr;
}

std::string axis_of(const StudyResult& r, const std::string& scene) {
  auto it = r.axes.find(scene);
  return it == r.axes.end() ? "triangles" : it->second;
}

// The distinct pixel counts a scene was measured at, ascending.
std::vector<double> pixel_counts(const StudyResult& r, const std::string& scene) {
  std::vector<double> out;
  for (const Measurement& m : r.points)
    if (m.scene == scene &&
        std::none_of(out.begin(), out.end(), [&](double p) { return same_value(p, m.pixels); }))
      out.push_back(m.pixels);
  std::sort(out.begin(), out.end());
  return out;
}

// The pixel count of the scene's main chart: the study's image size when points were taken
// there, otherwise the one with the most points.
double main_pixels(const StudyResult& r, const std::string& scene) {
  const double study = double(r.width) * r.height;
  std::map<double, int> count;
  for (const Measurement& m : r.points)
    if (m.scene == scene) {
      if (same_value(m.pixels, study)) return study;
      ++count[m.pixels];
    }
  double best = study;
  int most = 0;
  for (const auto& [p, k] : count)
    if (k > most) best = p, most = k;
  return best;
}

// A measured point as the chart draws it: its Harrell–Davis median and its spread.
ChartPoint chart_point(const Measurement& m, double x, const std::string& what) {
  ChartPoint p;
  p.x = x;
  p.typical = typical_seconds(m);
  const std::vector<double> seconds = all_seconds(m);
  const auto [lo, hi] = std::minmax_element(seconds.begin(), seconds.end());
  p.low = lo == seconds.end() ? p.typical : *lo;
  p.high = hi == seconds.end() ? p.typical : *hi;
  p.tooltip =
      fmt::format("{}, {}: {} ms (fastest {}, slowest {}; {} repetitions in {} runs)", m.renderer,
                  what, format_number(1e3 * p.typical), format_number(1e3 * p.low),
                  format_number(1e3 * p.high), seconds.size(), m.runs.size());
  return p;
}

// One renderer's series on a chart of `scene`: the points `keep` selects, at the x `x_of` gives
// (named `x_name` in their tooltips), and its fitted model as `model(fit, x)`.
template <typename Keep, typename X, typename Model>
ChartSeries series_of(const StudyResult& r, const std::string& renderer, const Colours& colours,
                      const std::string& scene, const std::string& x_name, Keep keep, X x_of,
                      Model model) {
  ChartSeries s;
  s.name = renderer;
  s.colour = colours.at(renderer);
  for (const Measurement& m : r.points)
    if (m.renderer == renderer && m.scene == scene && keep(m)) {
      const double x = x_of(m);
      s.points.push_back(chart_point(m, x, x_name + " = " + format_number(x)));
    }
  const ModelFit* fit = fit_of(r, renderer, scene);
  if (fit && !fit->coefficients.empty()) {
    const ModelFit f = *fit;
    s.model = [f, model](double x) { return model(f, x); };
    s.fits = f.fits;
  }
  return s;
}

// The points' x range: the swept range drawn unshaded.
void set_swept_range(ChartSpec& spec) {
  bool any = false;
  for (const ChartSeries& s : spec.series)
    for (const ChartPoint& p : s.points) {
      spec.swept_low = any ? std::min(spec.swept_low, p.x) : p.x;
      spec.swept_high = any ? std::max(spec.swept_high, p.x) : p.x;
      any = true;
    }
}

// "(95%: 107 – 154)", an open end as "…"; nothing without an interval.
std::string interval_words(const Interval& i) {
  if (std::isnan(i.low) && std::isnan(i.high)) return "";
  auto end = [](double v) { return std::isfinite(v) ? format_number(v) : std::string("…"); };
  return fmt::format(" (95%: {} – {})", end(i.low), end(i.high));
}

// The chart's mark of the `index`th crossover drawn on it.
ChartCrossing chart_crossing(const Crossover& c, size_t index) {
  ChartCrossing x;
  x.tag = fmt::format("{}", index + 1);
  x.value = c.value;
  x.low = c.ci95.low;
  x.high = c.ci95.high;
  x.measured = c.measured;
  x.label = fmt::format("{} = {} at {} {}{}{}", c.a, c.b, format_number(c.value), c.axis,
                        interval_words(c.ci95), c.measured ? "" : " (extrapolated)");
  return x;
}

// Time against the swept axis at the scene's main pixel count; `id` the chart's element id.
ChartSpec axis_chart(const StudyResult& r, const std::string& scene, const std::string& id,
                     const Colours& colours) {
  const double pixels = main_pixels(r, scene);
  const std::string axis = axis_of(r, scene);
  ChartSpec spec;
  spec.id = id;
  spec.title =
      fmt::format("{}: frame time against {} at {} pixels", scene, axis, format_number(pixels));
  spec.x_label = axis == "depth" ? "N (occluders' depth)" : "N (" + axis + ")";
  spec.y_label = "frame time (s)";
  for (const std::string& name : renderer_names(r))
    spec.series.push_back(series_of(
        r, name, colours, scene, "N",
        [&](const Measurement& m) { return same_value(m.pixels, pixels); },
        [](const Measurement& m) { return m.n; },
        [pixels](const ModelFit& f, double n) { return predict_seconds(f, pixels, n); }));
  set_swept_range(spec);
  for (const Crossover& c : r.crossovers)
    if (c.scene == scene && c.axis != "pixels" && (c.pixels <= 0 || same_value(c.pixels, pixels)))
      spec.crossings.push_back(chart_crossing(c, spec.crossings.size()));
  return spec;
}

// The N of a scene measured at two pixel counts or more, ascending.
std::vector<double> pixel_swept_ns(const StudyResult& r, const std::string& scene) {
  std::map<double, std::set<double>> pixels_at;
  for (const Measurement& m : r.points)
    if (m.scene == scene) pixels_at[m.n].insert(m.pixels);
  std::vector<double> out;
  for (const auto& [n, pixels] : pixels_at)
    if (pixels.size() >= 2) out.push_back(n);
  return out;
}

// Time against the pixel count at one N.
ChartSpec pixel_chart(const StudyResult& r, const std::string& scene, double n,
                      const std::string& id, const Colours& colours) {
  ChartSpec spec;
  spec.id = id;
  spec.title = fmt::format("{}: frame time against pixels at N = {}", scene, format_number(n));
  spec.x_label = "P (pixels)";
  spec.y_label = "frame time (s)";
  for (const std::string& name : renderer_names(r))
    spec.series.push_back(series_of(
        r, name, colours, scene, "P", [&](const Measurement& m) { return same_value(m.n, n); },
        [](const Measurement& m) { return m.pixels; },
        [n](const ModelFit& f, double p) { return predict_seconds(f, p, n); }));
  set_swept_range(spec);
  for (const Crossover& c : r.crossovers)
    if (c.scene == scene && c.axis == "pixels" && same_value(c.n, n))
      spec.crossings.push_back(chart_crossing(c, spec.crossings.size()));
  return spec;
}

// What the chart's marks mean: each renderer's colour and whether its model fits, then the
// crossovers' and the unmeasured range's marks.
std::string legend_html(const ChartSpec& spec) {
  std::vector<std::string> keys;
  for (const ChartSeries& s : spec.series) {
    const std::string dash = s.fits ? "" : " stroke-dasharray=\"5 3\"";
    const std::string state = !s.model ? "no model" : s.fits ? "model fits" : "model does not fit";
    keys.push_back(present::drawing_key(
        fmt::format("<line x1=\"1\" x2=\"29\" y1=\"7\" y2=\"7\" stroke=\"{0}\" "
                    "stroke-width=\"2\"{1}/><circle cx=\"15\" cy=\"7\" r=\"3.5\" "
                    "fill=\"{0}\"/>",
                    escape_html(s.colour), s.model ? dash : " stroke-opacity=\"0\""),
        fmt::format("<b>{}</b> ({} points; {})", escape_html(s.name), s.points.size(), state)));
  }
  auto any = [&](bool measured) {
    return std::any_of(spec.crossings.begin(), spec.crossings.end(),
                       [&](const ChartCrossing& c) { return c.measured == measured; });
  };
  if (any(true))
    keys.push_back(
        present::drawing_key("<rect x=\"4\" y=\"0\" width=\"22\" height=\"14\" fill=\"#f0a500\" "
                             "fill-opacity=\".25\"/><line x1=\"15\" x2=\"15\" y1=\"0\" y2=\"14\" "
                             "stroke=\"#8a5a00\" stroke-width=\"1.5\"/>",
                             "crossover of the measured points, 95% interval shaded"));
  if (any(false))
    keys.push_back(present::drawing_key(
        "<line x1=\"15\" x2=\"15\" y1=\"0\" y2=\"14\" stroke=\"#7a8394\" "
        "stroke-width=\"1.5\" stroke-dasharray=\"4 3\"/>",
        "crossover of the fitted models outside the swept range (extrapolated)"));
  for (const ChartCrossing& c : spec.crossings)
    keys.push_back(present::custom_key("crossover-key", "<b class=\"tag\">" + escape_html(c.tag) +
                                                            "</b> " + html_with_powers(c.label)));
  keys.push_back(present::drawing_key(
      "<rect x=\"2\" y=\"0\" width=\"26\" height=\"14\" fill=\"#eceef2\"/>", "not measured"));
  return present::legend(keys);
}

// A chart in its figure, with its legend and what the marks are.
std::string figure_html(const ChartSpec& spec, const std::string& caption) {
  return fmt::format("<figure class=\"chart-figure\">{}{}<figcaption>{}</figcaption></figure>\n",
                     loglog_chart_svg(spec), legend_html(spec), caption);
}

const char* const kMarksCaption =
    "Points: the Harrell–Davis median of each point's repetitions, the bar from the fastest to "
    "the slowest. Curves: the fitted cost model. ";

// A coefficient with its interval, or why it has none.
std::string coefficient_html(const Coefficient& c) {
  if (!c.identifiable) return escape_html(c.name) + ": not identifiable (folded into a)";
  return html_with_powers(coefficient_text(c));
}

// One row of the models table.
std::string model_row(const RendererModels& m, const ModelFit& f, const Colours& colours) {
  std::string coefs = "<ul class=\"coefs\">";
  for (const Coefficient& c : f.coefficients) coefs += "<li>" + coefficient_html(c) + "</li>";
  coefs += "</ul>";
  const std::string form = f.formula.empty() ? formula(m.form) : f.formula;
  auto colour = colours.find(m.name);
  return fmt::format(
      "<tr data-renderer=\"{0}\"><td>{1}{0}</td>"
      "<td>{2}</td><td>{3}</td><td class=\"num\">{4:.3f}</td><td class=\"num\">{5:.0f}%</td>"
      "<td class=\"num\">{6:.0f}%</td><td class=\"num\">{7}</td><td class=\"{8}\">{9}</td></tr>\n",
      escape_html(m.name), present::swatch(colour == colours.end() ? "#888" : colour->second),
      escape_html(form), coefs, f.r2, 100 * f.max_rel_residual, 100 * f.loo_rel_error, f.points,
      f.fits ? "good" : "bad", escape_html(f.verdict));
}

// Each renderer's model of one scene.
std::string models_table(const StudyResult& r, const std::string& scene, const Colours& colours) {
  std::string rows;
  for (const RendererModels& m : r.models) {
    auto it = m.fits.find(scene);
    if (it != m.fits.end()) rows += model_row(m, it->second, colours);
  }
  if (rows.empty()) return "<p>No model was fitted.</p>\n";
  return "<div class=\"scroll\"><table class=\"models\"><tr><th>renderer</th><th>model</th>"
         "<th>coefficients (95% interval)</th><th>R²</th><th>largest residual</th>"
         "<th>leave-one-out error</th><th>points</th><th>verdict</th></tr>\n" +
         rows + "</table></div>\n";
}

// The crossovers and dominance of one scene, as study.md says them.
std::string conclusions_html(const StudyResult& r, const std::string& scene) {
  std::string items;
  for (const Crossover& c : r.crossovers)
    if (c.scene == scene)
      items += fmt::format("<li class=\"crossover-sentence\">{}</li>\n",
                           html_with_powers(crossover_sentence(r, c)));
  for (const Dominance& d : r.dominance)
    if (d.scene == scene)
      items += fmt::format("<li class=\"dominance-sentence\">{}</li>\n",
                           html_with_powers(dominance_sentence(r, d)));
  for (const PredictionCheck& c : r.checks)
    if (c.scene == scene)
      items += fmt::format("<li class=\"check-sentence {}\">Checked after the fit: {}</li>\n",
                           c.verdict, html_with_powers(check_sentence(c)));
  for (const Comparison& c : r.comparisons)
    if (c.scene == scene && !c.inconclusive.empty())
      items +=
          fmt::format("<li class=\"inconclusive\">{} and {} along {}: nothing concluded: {}</li>\n",
                      escape_html(c.a), escape_html(c.b), escape_html(c.axis),
                      html_with_powers(c.inconclusive));
  if (items.empty()) return "";
  return "<h3>Conclusions</h3>\n<ul class=\"conclusions\">\n" + items + "</ul>\n";
}

// One scene family, the `index`th: its charts, its crossovers and its models.
std::string scene_section(const StudyResult& r, size_t index, const Colours& colours) {
  const std::string& scene = r.scenes[index];
  const std::string axis = axis_of(r, scene);
  std::string o =
      fmt::format("<section class=\"scene\" data-scene=\"{0}\"><h2>{0}</h2>\n", escape_html(scene));
  const std::string id = fmt::format("chart-{}", index + 1);
  const ChartSpec main = axis_chart(r, scene, id, colours);
  o += figure_html(main, html_with_powers(fmt::format(
                             "Frame time against {} at {} pixels ({}×{}), log-log. ", axis,
                             format_number(main_pixels(r, scene)), r.width, r.height)) +
                             kMarksCaption);
  if (pixel_counts(r, scene).size() > 1)
    for (double n : pixel_swept_ns(r, scene))
      o += figure_html(pixel_chart(r, scene, n, fmt::format("{}-pixels-{}", id, n), colours),
                       html_with_powers(fmt::format("Frame time against pixels at N = {} {}, "
                                                    "log-log. ",
                                                    format_number(n), axis)) +
                           kMarksCaption);
  o += conclusions_html(r, scene);
  o += builds_html(r, scene);
  for (const FamilyMemory& m : r.memory)
    if (m.scene == scene && !memory_sentence(m).empty())
      o += "<p class=\"memory\">" + html_with_powers(memory_sentence(m)) + "</p>\n";
  o += "<h3>Cost models</h3>\n" + models_table(r, scene, colours);
  return o + "</section>\n";
}

// What was run, and what stopped it short.
std::string header_html(const StudyResult& r) {
  std::string scenes;
  for (const std::string& s : r.scenes) scenes += (scenes.empty() ? "" : ", ") + s;
  std::string o = fmt::format("<h1>rvr study: {}</h1>\n", escape_html(scenes));
  if (!r.command.empty()) o += "<pre class=\"cmd\">" + escape_html(r.command) + "</pre>\n";
  o += "<p class=\"scope\"><b>Scope.</b> " + html_with_powers(scope_text(r)) + "</p>\n";
  o += "<p class=\"method\"><b>Method.</b> " + html_with_powers(method_text(r)) + "</p>\n";
  if (!r.no_conclusion.empty())
    o += "<div class=\"warn no-conclusion\"><b>No conclusion:</b> " +
         html_with_powers(r.no_conclusion) + ".</div>\n";
  const std::vector<std::string> headline = headline_sentences(r);
  if (!headline.empty()) {
    o += "<h2>Where the pixel-major loop overtakes the triangle-major one</h2>\n<ul "
         "class=\"headline\">";
    for (const std::string& h : headline) o += "<li>" + html_with_powers(h) + "</li>";
    o += "</ul>\n";
  }
  if (r.interrupted)
    o += "<div class=\"warn interrupted\"><b>Interrupted:</b> the sweep was stopped before its "
         "end; everything below is from the points measured until then.</div>\n";
  for (const std::string& note : r.notes)
    o += "<div class=\"warn note\"><b>Note:</b> " + html_with_powers(note) + ".</div>\n";
  return o;
}

// The machine the study ran on, and its state before and after the sweep.
std::string machine_html(const StudyResult& r) {
  const MachineInfo& m = r.machine;
  std::string o = "<h2>Machine</h2>\n<dl class=\"machine\">";
  o += fmt::format("<dt>CPU</dt><dd>{}</dd><dt>threads</dt><dd>{}</dd><dt>kernels</dt><dd>{}</dd>",
                   escape_html(m.cpu), m.threads, escape_html(m.kernels));
  for (const auto& [name, version] : m.versions)
    o += fmt::format("<dt>{}</dt><dd>{}</dd>", escape_html(name), escape_html(version));
  o += fmt::format("<dt>before the sweep</dt><dd>{}</dd><dt>after</dt><dd>{}</dd>",
                   escape_html(describe(r.system_before)), escape_html(describe(r.system_after)));
  return o + "</dl>\n";
}

// Full mode: each renderer's error against raytrace in each effect's mask.
std::string technique_error_html(const StudyResult& r) {
  const std::vector<std::string> sentences = technique_error_sentences(r);
  if (sentences.empty()) return "";
  std::string o =
      "<h2>Each technique's error</h2>\n<p>Each renderer's frame of every point against "
      "raytrace's, in the mask of the pixels each effect touches (from the tracer's "
      "ray tree). Exact, not sampled.</p>\n<ul class=\"technique-error\">";
  for (const std::string& s : sentences) o += "<li>" + html_with_powers(s) + "</li>";
  return o + "</ul>\n";
}

}  // namespace

std::string study_html(const StudyResult& r) {
  const Colours colours = renderer_colours(r);
  std::string scenes;
  for (const std::string& s : r.scenes) scenes += (scenes.empty() ? "" : ", ") + s;
  std::string o = present::page_start("rvr study: " + scenes, present::PageWidth::Reading);
  o += header_html(r);
  for (size_t i = 0; i < r.scenes.size(); ++i) o += scene_section(r, i, colours);
  o += technique_error_html(r);
  o += counted_work_html(r);
  o += machine_html(r);
  return o + present::page_end();
}

}  // namespace rvr::study
