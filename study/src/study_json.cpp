// study.json (see study_json.h).
#include "rvr/study/study_json.h"

#include <stddef.h>

#include <cmath>
#include <initializer_list>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/counted_work.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"
#include "rvr/study/memory_estimate.h"
#include "rvr/study/scene_changes.h"
#include "rvr/study/sweep_plan.h"
#include "rvr/study/system_probe.h"

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
          {"misfit", number(f.misfit)},
          {"repetition_noise", number(f.repetition_noise)},
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
                   {"range", json::array({c.range_low, c.range_high})},
                   {"below", {{"points", c.below_points}, {"ratio", number(c.below_ratio)}}},
                   {"above", {{"points", c.above_points}, {"ratio", number(c.above_ratio)}}},
                   {"contradicted", c.contradicted}});
  return out;
}

json comparisons_json(const StudyResult& r) {
  json out = json::array();
  for (const Comparison& c : r.comparisons) {
    json points = json::array();
    for (const PointComparison& p : c.points)
      points.push_back({{"at", p.at},
                        {"ratio", number(p.ratio)},
                        {"trend", number(p.trend)},
                        {"ci95", interval(p.ci95)},
                        {"p", number(p.p)},
                        {"faster", p.faster < 0   ? json(c.a)
                                   : p.faster > 0 ? json(c.b)
                                                  : json(nullptr)}});
    out.push_back({{"a", c.a},
                   {"b", c.b},
                   {"scene", c.scene},
                   {"axis", c.axis},
                   {"pixels", c.pixels},
                   {"n", c.n},
                   {"point_noise", number(c.point_noise)},
                   {"dof", number(c.dof)},
                   {"inconclusive", c.inconclusive.empty() ? json(nullptr) : json(c.inconclusive)},
                   {"points", points}});
  }
  return out;
}

json system_json(const SystemSnapshot& s) {
  return {{"at", number(s.at)},
          {"known", s.known},
          {"cpus", s.cpus},
          {"load", json::array({number(s.load1), number(s.load5), number(s.load15)})},
          {"other_busy", number(s.other_busy)},
          {"steal", number(s.steal)},
          {"mhz", s.mhz > 0 ? json(s.mhz) : json(nullptr)},
          {"governor", s.governor.empty() ? json(nullptr) : json(s.governor)}};
}

json sessions_json(const StudyResult& r) {
  json out = json::array();
  for (const SessionInfo& s : r.sessions)
    out.push_back({{"kind", s.kind}, {"study", s.study}, {"system", system_json(s.system)}});
  return out;
}

// Each renderer's preparation per point, and the frames per scene change (scene_changes.h).
void builds_json(const StudyResult& r, json& doc) {
  json builds = json::array();
  for (const BuildCost& b : r.builds)
    builds.push_back({{"renderer", b.renderer},
                      {"scene", b.scene},
                      {"n", b.n},
                      {"pixels", b.pixels},
                      {"prepare_seconds", number(b.prepare_seconds)},
                      {"range", json::array({number(b.low), number(b.high)})},
                      {"ns_per_triangle", number(b.ns_per_triangle)},
                      {"runs", b.runs}});
  doc["builds"] = builds;
  json changes = json::array();
  for (const SceneChange& c : r.scene_changes)
    changes.push_back({{"a", c.a},
                       {"b", c.b},
                       {"scene", c.scene},
                       {"n", c.n},
                       {"pixels", c.pixels},
                       {"frame_a", number(c.frame_a)},
                       {"frame_b", number(c.frame_b)},
                       {"prepare_a", number(c.prepare_a)},
                       {"prepare_b", number(c.prepare_b)},
                       {"frames", number(c.frames)},
                       {"ci95", interval(c.ci95)}});
  doc["scene_changes"] = changes;
}

// Each family's memory estimate (memory_estimate.h).
json memory_json(const StudyResult& r) {
  json out = json::array();
  auto line = [](const LinearBytes& l) { return json{{"fixed", l.fixed}, {"per_n", l.per_n}}; };
  for (const FamilyMemory& m : r.memory) {
    json probes = json::array();
    for (const MemoryProbe& p : m.probes) probes.push_back(json::parse(memory_probe_json(p)));
    json renderers = json::object();
    for (size_t k = 0; k < m.renderers.size(); ++k)
      renderers[m.renderers[k]] = {{"retained", line(m.model.retained[k])},
                                   {"prepare_peak", line(m.model.prepare_peak[k])},
                                   {"frame_peak", line(m.model.frame_peak[k])}};
    json points = json::array();
    for (const PointMemory& p : m.points) {
      json parts = json::object();
      for (size_t k = 0; k < m.renderers.size(); ++k)
        parts[m.renderers[k]] = {{"retained", p.renderer_bytes[k]},
                                 {"prepare_peak", p.build_peak_bytes[k]}};
      points.push_back({{"n", p.n},
                        {"peak_bytes", p.peak_bytes},
                        {"scene_bytes", p.scene_bytes},
                        {"renderers", parts},
                        {"fits", p.fits}});
    }
    out.push_back({{"scene", m.scene},
                   {"renderer_order", m.renderers},
                   {"probes", probes},
                   {"model",
                    {{"baseline", line(m.model.baseline)},
                     {"scene", line(m.model.scene)},
                     {"scene_peak", line(m.model.scene_peak)},
                     {"renderers", renderers}}},
                   {"available_bytes", m.available_bytes},
                   {"usable_bytes", m.usable_bytes},
                   {"points", points},
                   {"max_n", m.max_n},
                   {"dropped", m.dropped}});
  }
  return out;
}

void conclusions_json(const StudyResult& r, json& doc) {
  json dominance = json::array();
  for (const Dominance& d : r.dominance) {
    json contrary = json::array();
    for (size_t k = 0; k < d.contrary.size(); ++k)
      contrary.push_back({{"at", d.contrary[k]}, {"ratio", number(d.contrary_ratios[k])}});
    dominance.push_back({{"faster", d.faster},
                         {"slower", d.slower},
                         {"scene", d.scene},
                         {"axis", d.axis},
                         {"min_ratio", number(d.min_ratio)},
                         {"at", d.at},
                         {"pixels", d.pixels},
                         {"n", d.n},
                         {"range", json::array({d.range_low, d.range_high})},
                         {"significant", d.significant},
                         {"points", d.points},
                         {"significant_range",
                          json::array({number(d.significant_low), number(d.significant_high)})},
                         {"contrary", contrary}});
  }
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
  auto name_or_null = [](const std::string& s) { return s.empty() ? json(nullptr) : json(s); };
  for (const PredictionCheck& c : r.checks)
    checks.push_back({{"a", c.a},
                      {"b", c.b},
                      {"scene", c.scene},
                      {"axis", c.axis},
                      {"crossover", number(c.crossover)},
                      {"extrapolated", c.extrapolated},
                      {"at", number(c.at)},
                      {"pixels", c.pixels},
                      {"n", c.n},
                      {"predicted_faster", name_or_null(c.predicted_faster)},
                      {"measured_faster", name_or_null(c.measured_faster)},
                      {"ratio", number(c.ratio)},
                      {"ratio_ci95", interval(c.ratio_ci95)},
                      {"p", number(c.p)},
                      {"predicted_ratio", number(c.predicted_ratio)},
                      {"predicted_ci95", interval(c.predicted_ci95)},
                      {"verdict", c.verdict},
                      {"why", c.why}});
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
  builds_json(r, doc);
  doc["dominance"] = dominance;
  doc["scaling"] = scaling;
  doc["costs"] = costs;
}

// The cost models from counted work, the counts' scaling and the claims checked on counts.
void counted_work_json(const StudyResult& r, json& doc) {
  json models = json::array();
  for (const WorkModel& m : r.work_models) {
    json terms = json::array(), left_out = json::array();
    for (size_t j = 0; j < m.terms.size(); ++j)
      terms.push_back({{"counter", m.terms[j].name},
                       {"counts", j < m.counts.size() ? m.counts[j] : ""},
                       {"value", number(m.terms[j].value)},
                       {"ci95", interval(m.terms[j].ci95)}});
    for (const LeftOutCounter& l : m.left_out)
      left_out.push_back({{"counter", l.counter}, {"why", l.why}});
    models.push_back({{"renderer", m.renderer},
                      {"scene", m.scene},
                      {"terms", terms},
                      {"left_out", left_out},
                      {"r2", number(m.r2)},
                      {"max_rel_residual", number(m.max_rel_residual)},
                      {"loo_rel_error", number(m.loo_rel_error)},
                      {"misfit", number(m.misfit)},
                      {"repetition_noise", number(m.repetition_noise)},
                      {"points", m.points},
                      {"fits", m.fits},
                      {"verdict", m.verdict}});
  }
  json scaling = json::array();
  for (const CountScaling& c : r.count_scaling)
    scaling.push_back({{"renderer", c.renderer},
                       {"scene", c.scene},
                       {"counter", c.counter},
                       {"axis", c.axis},
                       {"n", c.n},
                       {"from", c.from},
                       {"to", c.to},
                       {"exponent", number(c.exponent)},
                       {"r2", number(c.r2)},
                       {"points", c.points}});
  json claims = json::array();
  for (const CountClaim& c : r.count_claims)
    claims.push_back({{"renderer", c.renderer},
                      {"scene", c.scene},
                      {"claim", c.claim},
                      {"quantity", c.quantity},
                      {"against", c.against},
                      {"intercept", number(c.intercept)},
                      {"slope", number(c.slope)},
                      {"r2", number(c.r2)},
                      {"exponent", number(c.exponent)},
                      {"range", json::array({c.from, c.to})},
                      {"points", c.points}});
  doc["work_models"] = models;
  doc["count_scaling"] = scaling;
  doc["count_claims"] = claims;
}

json numbers(const std::vector<double>& values) {
  json out = json::array();
  for (double v : values) out.push_back(number(v));
  return out;
}

json runs_json(const Measurement& m) {
  json out = json::array();
  for (const Run& run : m.runs) {
    json phases = json::object();
    for (const auto& [phase, seconds] : run.phases) phases[phase] = numbers(seconds);
    out.push_back({{"session", run.session},
                   {"prepare_seconds", number(run.prepare_seconds)},
                   {"seconds", numbers(run.seconds)},
                   {"order", run.order},
                   {"phases", phases},
                   {"reference_ratio", number(run.reference_ratio)},
                   {"busy", run.busy}});
  }
  return out;
}

json effect_errors_json(const std::vector<PointEffectError>& errors) {
  json out = json::array();
  for (const PointEffectError& e : errors)
    out.push_back({{"effect", e.effect},
                   {"pixels", e.pixels},
                   {"rmse", number(e.rmse)},
                   {"psnr_db", number(e.psnr_db)},
                   {"ssim", number(e.ssim)}});
  return out;
}

json points_json(const std::vector<Measurement>& points) {
  json out = json::array();
  for (const Measurement& m : points) {
    json counters = json::object();
    for (const auto& [name, value] : m.counters) counters[name] = number(value);
    json point = {{"renderer", m.renderer},
                  {"scene", m.scene},
                  {"scene_n", m.scene_n},
                  {"n", m.n},
                  {"width", m.width},
                  {"height", m.height},
                  {"pixels", m.pixels},
                  {"counters", counters},
                  {"runs", runs_json(m)},
                  {"seconds", number(typical_seconds(m))},
                  {"median", number(median_seconds(m))},
                  {"relative_mad", number(relative_mad(m))},
                  {"busy", m.busy()}};
    if (!m.effect_errors.empty()) point["effect_errors"] = effect_errors_json(m.effect_errors);
    out.push_back(std::move(point));
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
              {"sessions_per_point", r.sessions_per_point},
              {"noise_threshold", r.noise_threshold},
              {"seed", r.seed},
              {"run_id", r.run_id},
              {"merged_runs", r.merged_runs},
              {"bootstrap_replicates", r.bootstrap_replicates},
              {"machine",
               {{"cpu", r.machine.cpu},
                {"threads", r.machine.threads},
                {"kernels", r.machine.kernels},
                {"versions", r.machine.versions}}},
              {"system_before", system_json(r.system_before)},
              {"system_after", system_json(r.system_after)},
              {"sessions", sessions_json(r)},
              {"renderers", renderers_json(r)},
              {"comparisons", comparisons_json(r)},
              {"crossovers", crossovers_json(r)},
              {"no_conclusion", r.no_conclusion.empty() ? json(nullptr) : json(r.no_conclusion)},
              {"memory", memory_json(r)},
              {"notes", r.notes},
              {"interrupted", r.interrupted},
              {"shard", r.shard ? json{{"index", r.shard->index}, {"count", r.shard->count}}
                                : json(nullptr)}};
  conclusions_json(r, doc);
  counted_work_json(r, doc);
  doc["points"] = points_json(r.points);
  doc["check_points"] = points_json(r.check_points);
  return doc.dump(2) + "\n";
}

}  // namespace rvr::study
