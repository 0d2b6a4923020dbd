// metrics.json of `rvr compare`.
//
// metrics.json holds the fields docs/cli.md lists and docs/rvr-metrics-2.schema.json checks. JSON
// has no infinity or NaN: an infinite PSNR (identical colour) is written as 999.0, any other
// non-finite number as null.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <initializer_list>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "render_stats.h"
#include "report.h"
#include "report_text.h"
#include "rvr/compare/compare.h"
#include "rvr/compare/effect_errors.h"
#include "rvr/compare/mismatch_classes.h"

namespace rvr {
namespace {

using namespace report;

using ordered_json = nlohmann::ordered_json;

constexpr double kPsnrIdentical = 999.0;  // stands for +inf in metrics.json
// The document's shape (docs/rvr-metrics-2.schema.json). 2: pairs[], warnings, covered pixels
// and mismatch classes in place of mismatched_off_edge.
constexpr const char* kMetricsFormat = "rvr-metrics/2";

ordered_json number(double v) {
  return std::isfinite(v) ? ordered_json(v) : ordered_json(nullptr);
}

// The float as it reads (0.1), not as its double widening prints (0.10000000149011612).
ordered_json float_number(float v) {
  return number(std::isfinite(v) ? std::strtod(fmt("%.7g", v).c_str(), nullptr) : v);
}

ordered_json psnr_number(double v) {
  if (std::isinf(v) && v > 0) return kPsnrIdentical;
  return number(v);
}

// The metrics of one pair: visibility (with the mismatch classes), depth and colour.
ordered_json pair_metrics(const ComparisonMetrics& m) {
  const auto& v = m.visibility;
  ordered_json doc;
  doc["visibility"] = {{"pixels", v.pixels},
                       {"id_agreement", number(v.id_agreement)},
                       {"mismatched_pixels", v.mismatched_pixels},
                       {"covered_pixels", v.covered_pixels},
                       {"covered_fraction", number(v.covered_fraction)},
                       {"covered_agreement", number(v.covered_agreement)},
                       {"covered_a", v.covered_a},
                       {"covered_b", v.covered_b},
                       {"mismatch_classes",
                        {{"edge", v.classes.edge},
                         {"depth_precision", v.classes.depth_precision},
                         {"occlusion", v.classes.occlusion},
                         {"coverage", v.classes.coverage}}}};
  const auto& d = m.depth;
  ordered_json outliers = ordered_json::array();
  for (const DepthOutlier& o : d.worst_outliers)
    outliers.push_back({{"x", o.x},
                        {"y", o.y},
                        {"object", o.object},
                        {"rel_error", number(o.rel_error)},
                        {"depth_a", float_number(o.depth_a)},
                        {"depth_b", float_number(o.depth_b)},
                        {"cause", to_string(o.cause)}});
  doc["depth"] = {{"max_rel_error", number(d.max_rel_error)},
                  {"mean_rel_error", number(d.mean_rel_error)},
                  {"p99_rel_error", number(d.p99_rel_error)},
                  {"p999_rel_error", number(d.p999_rel_error)},
                  {"outlier_threshold", kDepthOutlierThreshold},
                  {"outliers", d.outliers},
                  {"outliers_at_silhouettes", d.outliers_at_silhouettes},
                  {"outliers_on_analytic_spheres", d.outliers_on_analytic_spheres},
                  {"outliers_elsewhere", d.outliers_elsewhere},
                  {"outlier_pixels", outliers}};
  const auto& c = m.colour;
  doc["color"] = {{"rmse", number(c.rmse)},
                  {"psnr_db", psnr_number(c.psnr_db)},
                  {"max_abs", number(c.max_abs)},
                  {"ssim", number(c.ssim)}};
  if (m.lod.pixels > 0)
    doc["lod"] = {{"pixels", m.lod.pixels},
                  {"mean_abs", number(m.lod.mean_abs)},
                  {"p99_abs", number(m.lod.p99_abs)}};
  if (!m.effects.empty()) {
    ordered_json by_effect = ordered_json::array();
    for (const EffectError& e : m.effects) {
      ordered_json entry = {{"effect", e.effect},           {"pixels", e.pixels},
                            {"rmse", number(e.rmse)},       {"psnr_db", psnr_number(e.psnr_db)},
                            {"max_abs", number(e.max_abs)}, {"ssim", number(e.ssim)}};
      if (!m.answers_from.empty()) {
        ordered_json answers = ordered_json::array();
        for (const AnswerError& s : e.answers)
          answers.push_back({{"answer", s.answer},
                             {"pixels", s.pixels},
                             {"rmse", number(s.rmse)},
                             {"psnr_db", psnr_number(s.psnr_db)},
                             {"max_abs", number(s.max_abs)},
                             {"ssim", number(s.ssim)}});
        entry["answers"] = answers;
      }
      by_effect.push_back(entry);
    }
    doc["effects"] = {{"mask_from", m.effects_mask_from}, {"by_effect", by_effect}};
    if (!m.answers_from.empty()) doc["effects"]["answers_from"] = m.answers_from;
  }
  return doc;
}

ordered_json pair_files(const ReportPair& p) {
  ordered_json files = {{"diff", p.file("diff")},
                        {"depth_diff", p.file("depth_diff")},
                        {"id_mismatch", p.file("id_mismatch")},
                        {"mismatch_classes", p.file("mismatch_classes")}};
  if (!p.metrics.effects.empty()) files["effects"] = p.file("effects");
  if (!p.metrics.answers_from.empty()) files["answers"] = p.file("answers");
  return files;
}

}  // namespace

std::vector<ReportPair> report_pairs(const ReportInput& input) {
  if (!input.pairs.empty()) return input.pairs;
  ReportPair only;
  only.metrics = input.metrics;
  return {only};
}

std::string metrics_json(const ReportInput& input) {
  try {
    ordered_json doc;
    doc["format"] = kMetricsFormat;
    doc["scene"] = input.scene;
    doc["width"] = input.width;
    doc["height"] = input.height;
    doc["mode"] = input.mode;

    ordered_json renderers = ordered_json::object();
    std::vector<std::string> keys;  // the renderers' keys, in order
    for (const auto& r : input.renderers) {
      std::string key = r.name;
      for (int k = 2; renderers.contains(key); ++k) key = r.name + "-" + std::to_string(k);
      ordered_json stats = ordered_json::object();
      for (const auto& [name, value] : r.stats) stats[name] = stat_json<ordered_json>(name, value);
      renderers[key] = {{"seconds", number(r.seconds)},
                        {"warnings", r.warnings},
                        {"stats", stats},
                        {"info", r.info},
                        {"depth_format", r.depth_format},
                        {"image", r.image_file}};
      if (!r.cost_file.empty())
        renderers[key]["cost"] = {
            {"image", r.cost_file}, {"mean", number(r.cost_mean)}, {"scale", number(r.cost_scale)}};
      keys.push_back(key);
    }
    doc["renderers"] = renderers;
    doc["warnings"] = input.warnings;

    // The first pair at the top level, as a single-pair document has it; then every pair.
    const std::vector<ReportPair> pairs = report_pairs(input);
    auto key_of = [&](size_t i) { return i < keys.size() ? keys[i] : std::string(); };
    const ordered_json first = pair_metrics(pairs.front().metrics);
    for (const auto& [k, v] : first.items()) doc[k] = v;
    ordered_json compared = ordered_json::array();
    for (size_t i : {pairs.front().a, pairs.front().b})
      if (i < keys.size()) compared.push_back(keys[i]);
    ordered_json all = ordered_json::array();
    for (const ReportPair& p : pairs) {
      ordered_json entry = {{"compared", {key_of(p.a), key_of(p.b)}}};
      const ordered_json metrics = pair_metrics(p.metrics);
      for (const auto& [k, v] : metrics.items()) entry[k] = v;
      entry["files"] = pair_files(p);
      all.push_back(entry);
    }
    doc["pairs"] = all;
    doc["edge_tolerance_px"] = kEdgeTolerancePixels;

    // Extras.
    doc["compared"] = compared;
    doc["command"] = input.command_line;
    doc["heat_map_scale"] = float_number(input.heat_map_scale);
    doc["depth_diff_scale"] = {{"low", float_number(input.depth_diff_scale.low)},
                               {"high", float_number(input.depth_diff_scale.high)},
                               {"map", "log10"}};
    doc["files"] = pair_files(pairs.front());
    doc["files"]["report"] = "report.html";
    // Invalid UTF-8 in a path or command line must not make dump() throw.
    return doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  } catch (const std::exception& e) {
    // Only allocation failure can get here; still hand back valid JSON.
    ordered_json err = {{"error", std::string("metrics_json failed: ") + e.what()}};
    return err.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  }
}

}  // namespace rvr
