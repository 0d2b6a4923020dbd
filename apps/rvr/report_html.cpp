// report.html of `rvr compare`.
//
// report.html is one self-contained file: the images are embedded as base64 data URIs, the CSS
// and the few lines of script are inline, nothing is fetched from anywhere.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <initializer_list>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "colour_bar.h"
#include "data_uri.h"
#include "report.h"
#include "report_script.h"
#include "report_text.h"
#include "rvr/compare/compare.h"
#include "rvr/compare/effect_errors.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/effect_answer.h"
#include "rvr/core/expected.h"
#include "rvr/core/stats.h"
#include "rvr/present/html_escape.h"
#include "rvr/present/legend.h"
#include "rvr/present/page.h"
#include "timing_chart.h"

namespace rvr {
namespace {

using namespace report;

// A colour swatch as the captions use it.
std::string swatch(const float rgb[3]) {
  char hex[8];
  std::snprintf(hex, sizeof hex, "#%02x%02x%02x", int(std::lround(rgb[0] * 255)) & 0xff,
                int(std::lround(rgb[1] * 255)) & 0xff, int(std::lround(rgb[2] * 255)) & 0xff);
  return present::swatch(hex);
}

struct MetricRow {
  std::string group, name, value, why;
  bool flagged = false;
};

// A listed outlier's colour, on depth_diff.png and in its table: orange on an outline, blue on
// an analytic sphere (both expected), red elsewhere (a real disagreement).
const char* outlier_colour(DepthOutlierCause cause) {
  switch (cause) {
    case DepthOutlierCause::Silhouette:
      return "#ff9f1c";
    case DepthOutlierCause::AnalyticSphere:
      return "#4dabf7";
    case DepthOutlierCause::Elsewhere:
      break;
  }
  return "#ff1744";
}

// Rings over depth_diff.png around the listed depth outliers, in its pixel coordinates (the
// SVG stretches with the image), coloured by cause.
std::string outlier_marks(const DepthMetrics& depth, int width, int height) {
  if (depth.worst_outliers.empty() || width <= 0 || height <= 0) return "";
  std::ostringstream svg;
  const double r = std::max(4.0, 0.012 * std::max(width, height));
  svg << "<svg class=\"marks\" viewBox=\"0 0 " << width << " " << height
      << "\" preserveAspectRatio=\"none\" aria-hidden=\"true\">";
  for (const DepthOutlier& o : depth.worst_outliers)
    svg << "<circle cx=\"" << o.x + 0.5 << "\" cy=\"" << o.y + 0.5 << "\" r=\"" << r
        << "\" fill=\"none\" stroke-width=\"" << r / 4 << "\" stroke=\"" << outlier_colour(o.cause)
        << "\"/>";
  svg << "</svg>";
  return svg.str();
}

// Rows of the outlier table shown before the rest is folded away: enough to see the worst,
// few enough that the listing does not fill the page.
constexpr size_t kOutlierRowsShown = 10;

// Rows of the outlier table, from `begin` to `end` of the listed outliers.
std::string outlier_rows(const std::vector<DepthOutlier>& listed, size_t begin, size_t end) {
  std::ostringstream h;
  for (size_t k = begin; k < end && k < listed.size(); ++k) {
    const DepthOutlier& o = listed[k];
    h << "<tr><td class=\"num\">" << o.x << "</td><td class=\"num\">" << o.y
      << "</td><td class=\"num\">" << o.object << "</td><td class=\"num\">"
      << fmt("%.7g", o.depth_a) << "</td><td class=\"num\">" << fmt("%.7g", o.depth_b)
      << "</td><td class=\"num" << (o.cause == DepthOutlierCause::Elsewhere ? " bad" : "") << "\">"
      << fmt("%.3g", o.rel_error) << "</td><td>" << present::swatch(outlier_colour(o.cause))
      << to_string(o.cause) << "</td></tr>\n";
  }
  return h.str();
}

// The listed depth outliers as a table: where, which object, both depths, why; the first
// kOutlierRowsShown shown, the rest folded away.
std::string outlier_table(const DepthMetrics& depth, const std::string& name_a,
                          const std::string& name_b) {
  std::ostringstream h;
  h << "<h2>Depth outliers</h2>\n<p class=\"why\">" << depth.outliers
    << " pixels differ in depth by more than " << short_number(kDepthOutlierThreshold)
    << " (relative): " << depth.outliers_at_silhouettes << " on an object's outline, "
    << depth.outliers_on_analytic_spheres << " on analytic spheres, " << depth.outliers_elsewhere
    << " elsewhere. On an outline, a facet seen edge-on changes depth faster than the "
       "z-buffer's sub-pixel vertex snapping (1/256 pixel) can follow, so a pixel centre a hair "
       "outside one facet may be drawn on it while the tracer hits its neighbour. On an "
       "analytic sphere the tracer sees the sphere and the z-buffer the polygon it draws "
       "inside it: both depths lie between where the pixel's ray enters the sphere and where "
       "it enters the largest ball inside the polygon (--spheres mesh compares like with "
       "like). Both are expected. Anywhere else the renderers disagree. They are ringed on "
       "depth_diff.png (orange: outline, blue: analytic sphere, red: elsewhere).</p>\n";
  const std::vector<DepthOutlier>& listed = depth.worst_outliers;
  if (listed.empty()) return h.str();
  const std::string head =
      "<div class=\"scroll\"><table><thead><tr><th>x</th><th>y</th>"
      "<th>object</th><th>depth " +
      escape_html(name_a) + "</th><th>depth " + escape_html(name_b) +
      "</th><th>relative error</th><th>cause</th></tr></thead><tbody>\n";
  const std::string tail = "</tbody></table></div>\n";
  h << head << outlier_rows(listed, 0, kOutlierRowsShown) << tail;
  if (listed.size() > kOutlierRowsShown)
    h << "<details class=\"more-outliers\"><summary>The other " << listed.size() - kOutlierRowsShown
      << " listed</summary>\n"
      << head << outlier_rows(listed, kOutlierRowsShown, listed.size()) << tail << "</details>\n";
  if (depth.outliers > listed.size())
    h << "<p class=\"why\">The " << listed.size()
      << " largest are listed (metrics.json lists the same).</p>\n";
  return h.str();
}

// The legend of mismatch_classes.png: a swatch and what each class means.
std::string class_legend() {
  static const char* const kMeaning[] = {
      "",
      "edge: the pixel centre lies within the edge tolerance of an edge of a hit primitive (a "
      "rule tie)",
      "depth_precision: both hit, the two surfaces within the depth buffers' resolution of each "
      "other (z-fighting)",
      "occlusion: both hit, one surface farther than the other by more than that (a visibility "
      "error)",
      "coverage: a surface in one image only, away from its edges"};
  std::ostringstream h;
  // One line per class, wrapped within the card (a swatch hanging before its text).
  for (size_t c = 1; c < kMismatchClassColours.size(); ++c)
    h << "<span class=\"key\">" << swatch(kMismatchClassColours[c].data()) << kMeaning[c]
      << "</span>";
  return h.str();
}

// The classes of one pair as "edge 3, depth_precision 0, occlusion 0, coverage 1".
std::string class_counts(const MismatchCounts& n) {
  return "edge " + std::to_string(n.edge) + ", depth_precision " +
         std::to_string(n.depth_precision) + ", occlusion " + std::to_string(n.occlusion) +
         ", coverage " + std::to_string(n.coverage);
}

// The pairs after the first: a table of their figures and each one's class picture.
std::string other_pairs(const std::vector<ReportPair>& pairs, const std::vector<std::string>& names,
                        const std::vector<std::string>& class_uris) {
  if (pairs.size() < 2) return "";
  std::ostringstream h;
  h << "<h2>Every pair</h2>\n<div class=\"scroll\"><table><thead><tr><th>pair</th>"
       "<th>id agreement</th><th>covered</th><th>agreement over covered</th><th>edge</th>"
       "<th>depth_precision</th><th>occlusion</th><th>coverage</th><th>PSNR</th></tr></thead>"
       "<tbody>\n";
  for (const ReportPair& p : pairs) {
    const auto& v = p.metrics.visibility;
    const double psnr = p.metrics.colour.psnr_db;
    h << "<tr><td><b>" << escape_html(names[p.a]) << "</b> vs <b>" << escape_html(names[p.b])
      << "</b></td><td class=\"num\">" << fmt("%.5f", v.id_agreement) << "</td><td class=\"num\">"
      << fmt("%.4f", v.covered_fraction) << "</td><td class=\"num\">"
      << fmt("%.5f", v.covered_agreement) << "</td><td class=\"num\">" << v.classes.edge
      << "</td><td class=\"num\">" << v.classes.depth_precision << "</td><td class=\"num"
      << (v.classes.occlusion ? " bad" : "") << "\">" << v.classes.occlusion
      << "</td><td class=\"num" << (v.classes.coverage ? " bad" : "") << "\">" << v.classes.coverage
      << "</td><td class=\"num\">"
      << (std::isinf(psnr) && psnr > 0 ? std::string("&infin;") : fmt("%.2f dB", psnr))
      << "</td></tr>\n";
  }
  h << "</tbody></table></div>\n<div class=\"grid\">\n";
  for (size_t k = 1; k < pairs.size(); ++k)
    h << "<figure><img src=\"" << class_uris[k] << "\" alt=\"mismatch classes\"><figcaption><b>"
      << escape_html(pairs[k].file("mismatch_classes"))
      << "</b>: " << escape_html(names[pairs[k].a]) << " vs " << escape_html(names[pairs[k].b])
      << ": " << class_counts(pairs[k].metrics.visibility.classes) << ".</figcaption></figure>\n";
  h << "</div>\n";
  return h.str();
}

// The renderer names of every pair's indices (placeholders where the input lists fewer).
std::vector<std::string> renderer_names(const ReportInput& input,
                                        const std::vector<ReportPair>& pairs) {
  std::vector<std::string> names;
  for (const auto& r : input.renderers) names.push_back(r.name);
  for (const ReportPair& p : pairs)
    while (names.size() <= std::max(p.a, p.b)) names.push_back(names.empty() ? "A" : "B");
  return names;
}

// Every image the page embeds, as data URIs.
struct ReportImages {
  std::vector<std::string> renders, costs;    // per renderer; a cost URI is empty without a file
  std::string diff, id_mismatch, depth_diff;  // of the first pair
  std::string effects;                        // of the first pair; empty when no effect acts
  std::string answers;                        // of answers_pair; empty without one
  std::vector<std::string> classes;           // per pair
};

// The pair whose z-buffer answers the report shows: the first whose masks come from the other
// renderer (a tracer's or a hybrid's frame: the z-buffer against the rays), else the first with
// answers at all; nullptr when none has them.
const ReportPair* answers_pair(const std::vector<ReportPair>& pairs) {
  const ReportPair* any = nullptr;
  for (const ReportPair& p : pairs) {
    if (p.metrics.answers_from.empty()) continue;
    if (p.metrics.answers_from != p.metrics.effects_mask_from) return &p;
    if (!any) any = &p;
  }
  return any;
}

// Reads every image first, so that a missing file fails before any HTML is built.
Expected<ReportImages> embed_images(const ReportInput& input,
                                    const std::vector<ReportPair>& pairs) {
  ReportImages images;
  for (const auto& r : input.renderers) {
    RVR_TRY_ASSIGN(uri, data_uri(input.out_dir, r.image_file));
    images.renders.push_back(std::move(uri.value()));
  }
  for (const auto& r : input.renderers) {
    if (r.cost_file.empty()) {
      images.costs.emplace_back();
      continue;
    }
    RVR_TRY_ASSIGN(uri, data_uri(input.out_dir, r.cost_file));
    images.costs.push_back(std::move(uri.value()));
  }
  const ReportPair& first = pairs.front();
  for (auto [file, to] :
       {std::pair{"diff", &images.diff}, std::pair{"id_mismatch", &images.id_mismatch},
        std::pair{"depth_diff", &images.depth_diff}}) {
    RVR_TRY_ASSIGN(uri, data_uri(input.out_dir, first.file(file)));
    *to = std::move(uri.value());
  }
  if (!first.metrics.effects.empty()) {
    RVR_TRY_ASSIGN(uri, data_uri(input.out_dir, first.file("effects")));
    images.effects = std::move(uri.value());
  }
  if (const ReportPair* p = answers_pair(pairs)) {
    RVR_TRY_ASSIGN(uri, data_uri(input.out_dir, p->file("answers")));
    images.answers = std::move(uri.value());
  }
  for (const ReportPair& p : pairs) {
    RVR_TRY_ASSIGN(uri, data_uri(input.out_dir, p.file("mismatch_classes")));
    images.classes.push_back(std::move(uri.value()));
  }
  return images;
}

// The title, what was rendered, the command line and the verdict badges of the first pair.
std::string summary(const ReportInput& input, const std::string& title, const ReportPair& first) {
  const auto& vis = first.metrics.visibility;
  const auto& col = first.metrics.colour;
  std::ostringstream h;
  h << "<h1>" << escape_html(title) << "</h1>\n";
  h << "<div class=\"meta\"><span><b>scene</b> " << escape_html(input.scene)
    << "</span><span><b>size</b> " << input.width << "&times;" << input.height
    << "</span><span><b>mode</b> " << escape_html(input.mode) << "</span><span><b>pixels</b> "
    << vis.pixels << "</span></div>\n";
  if (!input.command_line.empty())
    h << "<pre class=\"cmd\">" << escape_html(input.command_line) << "</pre>\n";
  h << "<div class=\"badges\">"
    << "<span class=\"badge "
    << (vis.classes.occlusion + vis.classes.coverage == 0 ? "good" : "bad") << "\">"
    << "visibility errors (occlusion + coverage): " << vis.classes.occlusion + vis.classes.coverage
    << "</span>"
    << "<span class=\"badge " << (vis.covered_pixels == 0 ? "bad" : "neutral") << "\">covered "
    << fmt("%.2f", vis.covered_fraction * 100.0) << "%</span>"
    << "<span class=\"badge neutral\">id agreement " << fmt("%.4f", vis.id_agreement * 100.0)
    << "%</span>"
    << "<span class=\"badge neutral\">PSNR "
    << (std::isinf(col.psnr_db) && col.psnr_db > 0 ? std::string("&infin; (identical)")
                                                   : fmt("%.2f dB", col.psnr_db))
    << "</span><span class=\"badge neutral\">SSIM " << fmt("%.5f", col.ssim) << "</span></div>\n";
  return h.str();
}

// Every warning of the run and of each renderer, prominently; nothing when there is none.
std::string warnings(const ReportInput& input) {
  size_t warning_count = input.warnings.size();
  for (const auto& r : input.renderers) warning_count += r.warnings.size();
  if (warning_count == 0) return "";
  std::ostringstream h;
  h << "<div class=\"warn\"><h2>&#9888; Warnings (" << warning_count << ")</h2><ul>\n";
  for (const auto& w : input.warnings) h << "<li>" << escape_html(w) << "</li>\n";
  for (const auto& r : input.renderers)
    for (const auto& w : r.warnings)
      h << "<li><b>" << escape_html(r.name) << "</b>: " << escape_html(w) << "</li>\n";
  h << "</ul></div>\n";
  return h.str();
}

// The renders side by side, then (with two or more) the flip between the first two.
std::string renders(const ReportInput& input, const ReportImages& images, const std::string& name_a,
                    const std::string& name_b) {
  std::ostringstream h;
  h << "<h2>Renders</h2>\n<div class=\"grid\">\n";
  for (size_t i = 0; i < input.renderers.size(); ++i) {
    const auto& r = input.renderers[i];
    h << "<figure><img src=\"" << images.renders[i] << "\" alt=\"" << escape_html(r.name)
      << "\"><figcaption><b>" << escape_html(r.name) << "</b> &middot; "
      << escape_html(r.image_file) << " &middot; " << fmt_seconds(r.seconds)
      << "</figcaption></figure>\n";
  }
  h << "</div>\n";
  if (input.renderers.size() >= 2) {
    h << "<h2>Flip</h2>\n<div class=\"grid\"><figure><div class=\"flip\">"
      << "<img src=\"" << images.renders[0] << "\" alt=\"" << escape_html(name_a) << "\">"
      << "<img id=\"flip-top\" class=\"top\" src=\"" << images.renders[1] << "\" alt=\""
      << escape_html(name_b) << "\"></div>"
      << "<div class=\"flipctl\"><span>" << escape_html(name_a)
      << "</span><input id=\"flip-range\" type=\"range\" min=\"0\" max=\"100\" value=\"50\" "
      << "aria-label=\"slider between the two renders\"><span>" << escape_html(name_b)
      << "</span><button id=\"flip-button\" type=\"button\">flip</button></div>"
      << "<figcaption>Left of the cut: " << escape_html(name_a)
      << "; right of it: " << escape_html(name_b)
      << ". Drag the slider, or flip between the whole images.</figcaption></figure></div>\n";
  }
  return h.str();
}

// The depth scale's decades as ticks of its colour bar.
std::vector<std::pair<double, std::string>> depth_ticks(double low, double high) {
  std::vector<std::pair<double, std::string>> ticks;
  if (low > 0 && high > low) {
    const double decades = std::log10(high / low);
    // The ends are floats: 1e-2f is 0.0099999998, still a tick.
    for (double e = std::ceil(std::log10(low) - 1e-6); e <= std::log10(high) + 1e-6; e += 1)
      ticks.push_back({(e - std::log10(low)) / decades, short_number(std::pow(10.0, e))});
  }
  return ticks;
}

// The first pair's heat maps: colour difference, mismatch classes, id mismatches and depth.
std::string differences(const ReportInput& input, const ReportPair& first,
                        const ReportImages& images, const std::string& name_a,
                        const std::string& name_b) {
  const double low = input.depth_diff_scale.low, high = input.depth_diff_scale.high;
  std::ostringstream h;
  h << "<h2>Differences</h2>\n<div class=\"grid\">\n"
    << "<figure><img src=\"" << images.diff
    << "\" alt=\"colour difference heat map\"><figcaption><b>diff.png</b>: per pixel, the "
       "largest |difference| over R, G, B of the linear colours, on the inferno colour map "
       "(black = 0, yellow-white &ge; "
    << fmt("%g", input.heat_map_scale) << ")."
    << inferno_bar("bar-diff", "colour difference scale",
                   {{0.0, "0"},
                    {0.5, fmt("%g", input.heat_map_scale / 2)},
                    {1.0, "&ge; " + fmt("%g", input.heat_map_scale)}})
    << "</figcaption></figure>\n"
    << "<figure><img src=\"" << images.classes.front()
    << "\" alt=\"mismatch classes\"><figcaption><b>" << escape_html(first.file("mismatch_classes"))
    << "</b>: each pixel whose (object, primitive) id differs, coloured by why, over a dimmed "
       "grey version of "
    << escape_html(name_a) << " (the reference of the edge test):" << class_legend()
    << "</figcaption></figure>\n"
    << "<figure><img src=\"" << images.id_mismatch
    << "\" alt=\"object id mismatches\"><figcaption><b>id_mismatch.png</b>: pixels whose "
       "object id differs, in red, over a grey version of "
    << escape_html(name_a) << ".</figcaption></figure>\n"
    << "<figure><div class=\"marked\"><img src=\"" << images.depth_diff
    << "\" alt=\"relative depth difference\">"
    << outlier_marks(first.metrics.depth, input.width, input.height)
    << "</div><figcaption><b>depth_diff.png</b>: relative "
       "view-depth difference |d<sub>A</sub> &minus; d<sub>B</sub>| / max(d<sub>A</sub>, "
       "d<sub>B</sub>) of "
    << escape_html(name_a) << " and " << escape_html(name_b)
    << " where both hit something (whatever the ids), on a <b>log scale</b>: black &le; "
    << short_number(low) << ", each decade an equal stretch of the colour map, yellow-white "
    << "&ge; " << short_number(high) << ". <span class=\"nowrap\">" << swatch(kDepthDiffBackground)
    << "background in both</span>; <span class=\"nowrap\">" << swatch(kDepthDiffHitVsBackground)
    << "background in one, a hit in the other</span>."
    << inferno_bar("bar-depth", "relative depth difference scale, logarithmic",
                   depth_ticks(low, high))
    << "</figcaption></figure>\n</div>\n";
  return h.str();
}

// The first pair's effect masks (effects.png) with their legend and each effect's error; nothing
// when no effect acts.
std::string effect_masks(const ReportPair& first, const ReportImages& images) {
  if (images.effects.empty()) return "";
  std::ostringstream h;
  h << "<h2>Where the effects act</h2>\n<div class=\"grid\">\n<figure><img src=\"" << images.effects
    << "\" alt=\"effect masks\"><figcaption><b>" << escape_html(first.file("effects"))
    << "</b>: the pixels whose primary surface in " << escape_html(first.metrics.effects_mask_from)
    << "'s frame shows an effect, over a dimmed grey version of that frame (the lens, which "
       "acts on every pixel, where no other does):";
  for (const EffectKey& key : kEffectKeys) {
    const EffectError* error = nullptr;
    for (const EffectError& e : first.metrics.effects)
      if (e.effect == key.name) error = &e;
    if (!error) continue;
    h << "<span class=\"key\">" << swatch(key.rgb) << key.name << ": " << error->pixels
      << " pixels, PSNR "
      << (std::isinf(error->psnr_db) ? std::string("&infin;") : fmt("%.2f dB", error->psnr_db))
      << ", SSIM " << fmt("%.4f", error->ssim) << "</span>";
  }
  h << "</figcaption></figure>\n</div>\n";
  return h.str();
}

// How the z-buffer answered each effect (answers.png of answers_pair) with its legend, and the
// error of each answer inside each effect's mask: where each approximation's known failure
// lies. Nothing without answers.
std::string effect_answers(const std::vector<ReportPair>& pairs, const ReportImages& images) {
  const ReportPair* p = answers_pair(pairs);
  if (!p || images.answers.empty()) return "";
  const ComparisonMetrics& m = p->metrics;
  std::ostringstream h;
  h << "<h2>How the z-buffer answered them</h2>\n<div class=\"grid\">\n<figure><img src=\""
    << images.answers << "\" alt=\"z-buffer answers\"><figcaption><b>"
    << escape_html(p->file("answers")) << "</b>: the technique " << escape_html(m.answers_from)
    << " answered each pixel's effect with, over a dimmed grey version of its frame:";
  std::vector<bool> shown(kEffectAnswers, false);
  for (const EffectError& e : m.effects)
    for (const AnswerError& a : e.answers)
      for (size_t k = 1; k < kEffectAnswers; ++k)
        if (a.answer == effect_answer_name(EffectAnswer(k))) shown[k] = true;
  for (size_t k = 1; k < kEffectAnswers; ++k)
    if (shown[k])
      h << "<span class=\"key\">" << swatch(kAnswerColours[k])
        << effect_answer_name(EffectAnswer(k)) << "</span>";
  h << "</figcaption></figure>\n</div>\n<table>\n<tr><th>effect</th><th>answer</th>"
       "<th>pixels</th><th>PSNR</th><th>max</th><th>SSIM</th></tr>\n";
  for (const EffectError& e : m.effects)
    for (const AnswerError& a : e.answers)
      h << "<tr><td>" << e.effect << "</td><td>" << escape_html(a.answer) << "</td><td>" << a.pixels
        << "</td><td>"
        << (std::isinf(a.psnr_db) ? std::string("&infin;") : fmt("%.2f dB", a.psnr_db))
        << "</td><td>" << fmt("%.4g", a.max_abs) << "</td><td>" << fmt("%.4f", a.ssim)
        << "</td></tr>\n";
  h << "</table>\n";
  return h.str();
}

// Work per pixel: what each loop order pays where.
std::string work_per_pixel(const ReportInput& input, const ReportImages& images) {
  std::ostringstream h;
  h << "<h2>Work per pixel</h2>\n<div class=\"grid\">\n";
  for (size_t i = 0; i < input.renderers.size(); ++i) {
    const auto& r = input.renderers[i];
    if (r.cost_file.empty()) {
      h << "<figure><figcaption><b>" << escape_html(r.name)
        << "</b>: no per-pixel work reported.</figcaption></figure>\n";
      continue;
    }
    h << "<figure><img src=\"" << images.costs[i] << "\" alt=\"" << escape_html(r.name)
      << " work per pixel\"><figcaption><b>" << escape_html(r.cost_file) << "</b>: "
      << (r.stats.count("fragments.generated") ? "fragments generated per pixel (overdraw)"
                                               : "BVH nodes visited + primitive tests per pixel")
      << "; mean " << fmt("%.3g", r.cost_mean) << ", yellow-white &ge; " << fmt("%g", r.cost_scale)
      << " (the 99th percentile).</figcaption></figure>\n";
  }
  h << "</div>\n";
  return h.str();
}

// The first pair's metrics, each with what it means; flagged where it should be 0 and is not.
std::vector<MetricRow> metric_rows(const ComparisonMetrics& m) {
  const auto& vis = m.visibility;
  const auto& dep = m.depth;
  const auto& col = m.colour;
  const bool identical = std::isinf(col.psnr_db) && col.psnr_db > 0;
  std::vector<MetricRow> rows = {
      {"visibility", "pixels", std::to_string(vis.pixels), "width &times; height."},
      {"visibility", "id_agreement", fmt("%.6f", vis.id_agreement),
       "Fraction of pixels where both renders see the same object and the same primitive."},
      {"visibility", "mismatched_pixels", std::to_string(vis.mismatched_pixels),
       "Pixels whose (object, primitive) id differs."},
      {"visibility", "covered_fraction", fmt("%.6f", vis.covered_fraction),
       "Fraction of pixels where either render shows a surface.", vis.covered_pixels == 0},
      {"visibility", "covered_agreement", fmt("%.6f", vis.covered_agreement),
       "Fraction of those covered pixels whose ids agree; 0 when nothing is visible.",
       vis.covered_pixels == 0},
      {"visibility", "mismatch_classes.edge", std::to_string(vis.classes.edge),
       "Mismatches whose pixel centre lies within " + short_number(kEdgeTolerancePixels) +
           " pixel of an edge of a hit primitive: a tie the fill rules may break either way."},
      {"visibility", "mismatch_classes.depth_precision",
       std::to_string(vis.classes.depth_precision),
       "Both hit, and the two surfaces lie within the depth buffers' resolution of each other "
       "at that depth: z-fighting, decided by the depth format, not by the loop order."},
      {"visibility", "mismatch_classes.occlusion", std::to_string(vis.classes.occlusion),
       "Both hit, one surface farther than the other by more than that: a visibility error. "
       "Should be 0.",
       vis.classes.occlusion != 0},
      {"visibility", "mismatch_classes.coverage", std::to_string(vis.classes.coverage),
       "A surface in one render, background in the other, away from the surface's edges. "
       "Should be 0.",
       vis.classes.coverage != 0},
      {"depth", "max_rel_error", fmt("%.3g", dep.max_rel_error),
       "Largest |d<sub>A</sub> &minus; d<sub>B</sub>| / max(d<sub>A</sub>, d<sub>B</sub>) of "
       "view-axis depth over pixels where the ids agree (background excluded)."},
      {"depth", "mean_rel_error", fmt("%.3g", dep.mean_rel_error),
       "Mean of the same relative depth error."},
      {"depth", "p99_rel_error", fmt("%.3g", dep.p99_rel_error),
       "99th percentile of the same error: 99% of those pixels are at or below it."},
      {"depth", "p999_rel_error", fmt("%.3g", dep.p999_rel_error), "99.9th percentile."},
      {"depth", "outliers", std::to_string(dep.outliers),
       "Pixels whose relative depth error is above " + short_number(kDepthOutlierThreshold) +
           " (see Depth outliers below)."},
      {"depth", "outliers_at_silhouettes", std::to_string(dep.outliers_at_silhouettes),
       "Of those, on an object's outline: an edge-on facet under the z-buffer's vertex "
       "snapping. Expected."},
      {"depth", "outliers_on_analytic_spheres", std::to_string(dep.outliers_on_analytic_spheres),
       "Of those, on an analytic sphere, within what the z-buffer's polygon of it can differ "
       "from the sphere along the pixel's ray. Expected; 0 with --spheres mesh."},
      {"depth", "outliers_elsewhere", std::to_string(dep.outliers_elsewhere),
       "Of those, anywhere else: unexplained, a real disagreement. Should be 0.",
       dep.outliers_elsewhere != 0},
      {"color", "rmse", fmt("%.4g", col.rmse),
       "Root mean square difference of linear RGB over every pixel and channel."},
      {"color", "psnr_db",
       identical ? std::string("&infin; (999 in metrics.json)") : fmt("%.2f", col.psnr_db),
       "20&middot;log<sub>10</sub>(1 / rmse), peak value 1; higher is closer. Identical images "
       "have infinite PSNR, written as 999 in metrics.json."},
      {"color", "max_abs", fmt("%.4g", col.max_abs),
       "Largest absolute difference of one channel of one pixel (linear)."},
      {"color", "ssim", fmt("%.5f", col.ssim),
       "Structural similarity of the luminance of the colours clamped to [0, 1], 11&times;11 "
       "Gaussian window (&sigma; 1.5), averaged over the image; 1 = identical."},
  };
  const LodMetrics& lod = m.lod;
  if (lod.pixels > 0) {
    rows.push_back({"lod", "mean_abs", fmt("%.3g", lod.mean_abs),
                    "Mean |lod<sub>A</sub> &minus; lod<sub>B</sub>| in mip levels over the " +
                        std::to_string(lod.pixels) +
                        " pixels textured in both: how far the two loop orders' texture levels "
                        "of detail differ (docs/design.md, Textures)."});
    rows.push_back(
        {"lod", "p99_abs", fmt("%.3g", lod.p99_abs), "99th percentile of the same difference."});
  }
  for (const EffectError& e : m.effects)
    rows.push_back(
        {"effects", e.effect + " psnr_db",
         std::isinf(e.psnr_db) ? std::string("&infin; (999 in metrics.json)")
                               : fmt("%.2f", e.psnr_db),
         "The colour's PSNR over the " + std::to_string(e.pixels) + " pixels whose primary " +
             "surface in " + m.effects_mask_from + "'s frame shows " + e.effect + " (rmse " +
             fmt("%.4g", e.rmse) + ", max " + fmt("%.4g", e.max_abs) +
             "): the error where the effect acts, which the whole image's PSNR dilutes."});
  return rows;
}

std::string metrics_table(const std::vector<MetricRow>& rows) {
  std::ostringstream h;
  h << "<h2>Metrics</h2>\n<table><thead><tr><th>group</th><th>metric</th><th>value</th>"
       "<th>meaning</th></tr></thead><tbody>\n";
  for (const auto& row : rows)
    h << "<tr><td>" << row.group << "</td><td><code>" << row.name << "</code></td><td class=\"num"
      << (row.flagged ? " bad" : "") << "\">" << row.value << "</td><td class=\"why\">" << row.why
      << "</td></tr>\n";
  h << "</tbody></table>\n";
  return h.str();
}

// Timings: seconds and every "time.*" stat, one column per renderer (phases are many more
// than renderers, so the table grows down, not off the page's right edge).
std::string timings(const ReportInput& input) {
  std::ostringstream h;
  std::set<std::string> time_keys;
  for (const auto& r : input.renderers)
    for (const auto& [k, v] : r.stats)
      if (k.rfind("time.", 0) == 0) time_keys.insert(k);
  h << "<h2>Timings</h2>\n"
    << timing_chart(input.renderers)
    << "<p class=\"why small\">Each bar: the scene load "
       "(shared, outside the render call), the phases the renderer reports (time.* below) "
       "and, as <i>other</i>, the rest of its render call.</p>\n"
    << "<div class=\"scroll\"><table class=\"timings\"><thead><tr><th></th>";
  for (const auto& r : input.renderers) h << "<th class=\"num\">" << escape_html(r.name) << "</th>";
  h << "</tr></thead><tbody>\n<tr><td><b>seconds</b></td>";
  for (const auto& r : input.renderers)
    h << "<td class=\"num\">" << fmt_seconds(r.seconds) << "</td>";
  h << "</tr>\n<tr><td><b>relative</b></td>";
  const double base = input.renderers.empty() ? 0.0 : input.renderers[0].seconds;
  for (const auto& r : input.renderers)
    h << "<td class=\"num\">"
      << (base > 0 ? fmt("%.2f&times;", r.seconds / base) : std::string("n/a")) << "</td>";
  h << "</tr>\n";
  for (const auto& k : time_keys) {
    h << "<tr><td><code>" << escape_html(k) << "</code></td>";
    for (const auto& r : input.renderers) {
      auto it = r.stats.find(k);
      h << "<td class=\"num\">" << (it == r.stats.end() ? "&ndash;" : fmt_seconds(it->second))
        << "</td>";
    }
    h << "</tr>\n";
  }
  h << "<tr><td><b>warnings</b></td>";
  for (const auto& r : input.renderers) h << "<td class=\"num\">" << r.warnings.size() << "</td>";
  h << "</tr>\n</tbody></table></div>\n<p class=\"why small\">"
       "seconds: wall-clock time of the render call; relative: divided by the first "
       "renderer's; time.*: the phases each renderer reports.</p>\n";
  return h.str();
}

// Every renderer's information and counters, folded away.
std::string all_statistics(const ReportInput& input) {
  std::ostringstream h;
  for (const auto& r : input.renderers) {
    if (r.stats.empty()) continue;
    h << "<details><summary>All statistics of <b>" << escape_html(r.name) << "</b> ("
      << r.stats.size() << ")</summary><table><tbody>\n";
    for (const auto& [k, v] : r.info)
      h << "<tr><td><code>" << escape_html(k) << "</code></td><td class=\"num\">" << escape_html(v)
        << "</td></tr>\n";
    for (const auto& [k, v] : r.stats)
      h << "<tr><td><code>" << escape_html(k) << "</code></td><td class=\"num\">"
        << (stat_kind(k) == StatKind::Count && v == std::floor(v) ? fmt("%.0f", v) : fmt("%.6g", v))
        << "</td></tr>\n";
    h << "</tbody></table></details>\n";
  }
  return h.str();
}

std::string page_end(const ReportInput& input) {
  return "<footer>Written by rvr compare. Colour metrics use linear RGB with peak 1; the heat "
         "map scale is " +
         fmt("%g", input.heat_map_scale) + ".</footer>\n" +
         present::page_end(input.renderers.size() >= 2 ? kScript : "");
}

}  // namespace

Expected<std::string> report_html(const ReportInput& input) {
  try {
    const std::vector<ReportPair> pairs = report_pairs(input);
    const ReportPair& first = pairs.front();
    const std::vector<std::string> names = renderer_names(input, pairs);
    const std::string& name_a = names[first.a];
    const std::string& name_b = names[first.b];
    RVR_TRY_ASSIGN(images, embed_images(input, pairs));

    const std::string title = "rvr compare: " + name_a + " vs " + name_b + " on " + input.scene;
    std::ostringstream h;
    h << present::page_start(title, present::PageWidth::Wide) << summary(input, title, first)
      << warnings(input) << renders(input, *images, name_a, name_b)
      << differences(input, first, *images, name_a, name_b) << effect_masks(first, *images)
      << effect_answers(pairs, *images) << work_per_pixel(input, *images)
      << metrics_table(metric_rows(first.metrics))
      << outlier_table(first.metrics.depth, name_a, name_b)
      << other_pairs(pairs, names, images->classes) << timings(input) << all_statistics(input)
      << page_end(input);
    return h.str();
  } catch (const std::exception& e) {
    return internal_error(std::string("cannot build report.html: ") + e.what());
  }
}

}  // namespace rvr
