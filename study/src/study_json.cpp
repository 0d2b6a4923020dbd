// study.json (see study_json.h).
#include "rvr/study/study_json.h"

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study {
namespace {

using nlohmann::json;

json number(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

json interval(const Interval& i) {
  return json::array({number(i.low), number(i.high)});
}

json fit_json(const ModelFit& f) {
  json coefficients = json::object();
  for (const Coefficient& c : f.coefficients)
    coefficients[c.name] = {{"value", c.identifiable ? number(c.value) : json(nullptr)},
                            {"ci95", c.identifiable ? interval(c.ci95) : json(nullptr)},
                            {"identifiable", c.identifiable}};
  return {{"formula", f.formula},
          {"selection", f.selection},
          {"coefficients", coefficients},
          {"r2", number(f.r2)},
          {"max_rel_residual", number(f.max_rel_residual)},
          {"loo_rel_error", number(f.loo_rel_error)},
          {"points", f.points},
          {"fits", f.fits},
          {"verdict", f.verdict},
          {"fixed_pixels", f.fixed_pixels > 0 ? json(f.fixed_pixels) : json(nullptr)}};
}

json renderers_json(const StudyResult& r) {
  json out = json::object();
  for (const RendererModels& m : r.models) {
    json fits = json::object();
    for (const auto& [scene, f] : m.fits) fits[scene] = fit_json(f);
    out[m.name] = {{"loop_order", m.loop_order},
                   {"model", to_string(m.form)},
                   {"formula", formula(CostModel(m.form))},
                   {"fits", fits}};
  }
  return out;
}

json crossovers_json(const StudyResult& r) {
  json out = json::array();
  for (const Crossover& c : r.crossovers)
    out.push_back({{"a", c.a},
                   {"b", c.b},
                   {"scene", c.scene},
                   {"axis", c.axis},
                   {"value", number(c.value)},
                   {"ci95", interval(c.ci95)},
                   {"pixels", c.pixels},
                   {"n", c.n},
                   {"a_faster_below", c.a_faster_below},
                   {"measured", c.measured},
                   {"range", json::array({c.range_low, c.range_high})}});
  return out;
}

void conclusions_json(const StudyResult& r, json& doc) {
  json dominance = json::array();
  for (const Dominance& d : r.dominance)
    dominance.push_back({{"faster", d.faster},
                         {"slower", d.slower},
                         {"scene", d.scene},
                         {"axis", d.axis},
                         {"min_ratio", number(d.min_ratio)},
                         {"at", d.at},
                         {"pixels", d.pixels},
                         {"n", d.n},
                         {"range", json::array({d.range_low, d.range_high})}});
  json scaling = json::array();
  for (const ScalingExponent& s : r.scaling)
    scaling.push_back({{"renderer", s.renderer},
                       {"scene", s.scene},
                       {"axis", s.axis},
                       {"n", s.n},
                       {"from", s.from},
                       {"to", s.to},
                       {"exponent", number(s.exponent)}});
  json costs = json::array();
  for (const UnitCost& c : r.costs)
    costs.push_back({{"renderer", c.renderer},
                     {"scene", c.scene},
                     {"n", c.n},
                     {"seconds", number(c.seconds)},
                     {"ns_per_triangle", number(c.ns_per_triangle)},
                     {"ns_per_ray", number(c.ns_per_ray)}});
  json checks = json::array();
  for (const PredictionCheck& c : r.checks)
    checks.push_back({{"a", c.a},
                      {"b", c.b},
                      {"scene", c.scene},
                      {"axis", c.axis},
                      {"crossover", number(c.crossover)},
                      {"at", number(c.at)},
                      {"pixels", c.pixels},
                      {"predicted_faster", c.predicted_faster},
                      {"measured_faster", c.measured_faster},
                      {"ratio", number(c.ratio)},
                      {"holds", c.holds}});
  doc["checks"] = checks;
  json splits = json::array();
  for (const PhaseSplit& s : r.splits)
    splits.push_back({{"renderer", s.renderer},
                      {"scene", s.scene},
                      {"n", s.n},
                      {"pixels", s.pixels},
                      {"zbuffer_seconds", number(s.zbuffer_seconds)},
                      {"trace_seconds", number(s.trace_seconds)},
                      {"zbuffer_share", number(s.zbuffer_share)}});
  doc["splits"] = splits;
  doc["dominance"] = dominance;
  doc["scaling"] = scaling;
  doc["costs"] = costs;
}

json phases_json(const Measurement& m) {
  json out = json::object();
  for (const auto& [phase, seconds] : m.phases) {
    json values = json::array();
    for (double s : seconds) values.push_back(number(s));
    out[phase] = values;
  }
  return out;
}

json points_json(const StudyResult& r) {
  json out = json::array();
  for (const Measurement& m : r.points) {
    json seconds = json::array();
    for (double s : m.seconds) seconds.push_back(number(s));
    out.push_back({{"renderer", m.renderer},
                   {"scene", m.scene},
                   {"scene_n", m.scene_n},
                   {"n", m.n},
                   {"width", m.width},
                   {"height", m.height},
                   {"pixels", m.pixels},
                   {"seconds", seconds},
                   {"order", m.order},
                   {"median", number(median_seconds(m))},
                   {"hd_median", number(typical_seconds(m))},
                   {"relative_mad", number(relative_mad(m))},
                   {"reference_ratio", number(m.reference_ratio)},
                   {"phases", phases_json(m)},
                   {"busy", m.busy}});
  }
  return out;
}

}  // namespace

std::string study_json(const StudyResult& r) {
  json scenes = json::array();
  for (const std::string& s : r.scenes) scenes.push_back({{"name", s}, {"axis", r.axes.at(s)}});
  json doc = {{"format", kStudyFormat},
              {"command", r.command},
              {"scenes", scenes},
              {"renderer_order", r.renderers},
              {"width", r.width},
              {"height", r.height},
              {"mode", r.mode},
              {"budget_seconds", r.budget_seconds},
              {"elapsed_seconds", number(r.elapsed_seconds)},
              {"repetitions", r.repetitions},
              {"seed", r.seed},
              {"bootstrap_replicates", r.bootstrap_replicates},
              {"machine",
               {{"cpu", r.machine.cpu},
                {"threads", r.machine.threads},
                {"kernels", r.machine.kernels},
                {"versions", r.machine.versions}}},
              {"renderers", renderers_json(r)},
              {"crossovers", crossovers_json(r)},
              {"notes", r.notes},
              {"interrupted", r.interrupted},
              {"shard", r.shard ? json{{"index", r.shard->index}, {"count", r.shard->count}}
                                : json(nullptr)}};
  conclusions_json(r, doc);
  doc["points"] = points_json(r);
  return doc.dump(2) + "\n";
}

}  // namespace rvr::study
