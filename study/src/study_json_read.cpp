// Reading study.json back (see study_json.h): the request, the machine and every point with its
// repetitions. The conclusions in the file are computed from these, so they are checked for
// their type only and left for conclude() to compute again.
#include <fmt/format.h>
#include <stddef.h>
#include <stdint.h>

#include <algorithm>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/renderers/registry.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/measurement.h"
#include "rvr/study/study.h"
#include "rvr/study/study_json.h"
#include "rvr/study/sweep_plan.h"
#include "rvr/study/system_probe.h"

namespace rvr::study {
namespace {

using nlohmann::json;

// Thrown inside the reader, caught by read_study_json.
struct ReadError {
  std::string path;  // JSON path, e.g. "points[3].seconds[1]"
  std::string what;
};

[[noreturn]] void fail(std::string path, std::string what) {
  throw ReadError{std::move(path), std::move(what)};
}

std::string key_path(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

std::string index_path(const std::string& parent, size_t i) {
  return fmt::format("{}[{}]", parent, i);
}

std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::string:
      return "string " + v.dump();
    case json::value_t::array:
      return fmt::format("array of {}", v.size());
    case json::value_t::object:
      return "object";
    default:
      return v.dump();
  }
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

// The JSON value of each field, by path, with the checks every field needs.
class Fields {
 public:
  Fields(const json& obj, std::string path, std::vector<std::string> allowed)
      : obj_(obj), path_(std::move(path)) {
    if (!obj.is_object()) fail(where(), "must be an object, got " + describe(obj));
    for (const auto& item : obj.items())
      if (std::find(allowed.begin(), allowed.end(), item.key()) == allowed.end())
        fail(key_path(path_, item.key()), "unknown key; allowed: " + join(allowed));
  }

  std::string path(const char* key) const { return key_path(path_, key); }
  bool has(const char* key) const { return obj_.contains(key); }
  const json& at(const char* key) const {
    if (!obj_.contains(key)) fail(path(key), "is required");
    return obj_.at(key);
  }

  const std::string& string(const char* key) const {
    const json& v = at(key);
    if (!v.is_string()) fail(path(key), "must be a string, got " + describe(v));
    return v.get_ref<const std::string&>();
  }
  bool boolean(const char* key) const {
    const json& v = at(key);
    if (!v.is_boolean()) fail(path(key), "must be true or false, got " + describe(v));
    return v.get<bool>();
  }
  double number(const char* key, double low) const { return number_at(at(key), path(key), low); }
  double number_or_nan(const char* key) const {
    if (at(key).is_null()) return std::numeric_limits<double>::quiet_NaN();
    return number_at(at(key), path(key), -std::numeric_limits<double>::infinity());
  }
  uint64_t whole(const char* key, uint64_t low, uint64_t high) const {
    return whole_at(at(key), path(key), low, high);
  }
  const json& array(const char* key) const {
    if (!at(key).is_array()) fail(path(key), "must be an array, got " + describe(at(key)));
    return at(key);
  }
  const json& object(const char* key) const {
    if (!at(key).is_object()) fail(path(key), "must be an object, got " + describe(at(key)));
    return at(key);
  }

  static double number_at(const json& v, const std::string& path, double low) {
    if (!v.is_number()) fail(path, "must be a number, got " + describe(v));
    double d = v.get<double>();
    if (!(d >= low)) fail(path, fmt::format("must be >= {}, got {}", low, describe(v)));
    return d;
  }
  static uint64_t whole_at(const json& v, const std::string& path, uint64_t low, uint64_t high) {
    if (!v.is_number_unsigned() || v.get<uint64_t>() < low || v.get<uint64_t>() > high)
      fail(path, fmt::format("must be a whole number in {} .. {}, got {}", low, high, describe(v)));
    return v.get<uint64_t>();
  }

 private:
  std::string where() const { return path_.empty() ? "top level" : path_; }

  const json& obj_;
  std::string path_;
};

const std::vector<std::string> kTopKeys = {"format",
                                           "command",
                                           "scenes",
                                           "renderer_order",
                                           "width",
                                           "height",
                                           "mode",
                                           "budget_seconds",
                                           "elapsed_seconds",
                                           "repetitions",
                                           "sessions_per_point",
                                           "noise_threshold",
                                           "seed",
                                           "run_id",
                                           "merged_runs",
                                           "bootstrap_replicates",
                                           "machine",
                                           "system_before",
                                           "system_after",
                                           "sessions",
                                           "renderers",
                                           "comparisons",
                                           "crossovers",
                                           "no_conclusion",
                                           "dominance",
                                           "scaling",
                                           "costs",
                                           "checks",
                                           "notes",
                                           "interrupted",
                                           "shard",
                                           "points",
                                           "check_points",
                                           "splits"};
// The counted work's conclusions (counted_work.h), computed again like the others.
const std::vector<std::string> kCountedWorkKeys = {"work_models", "count_scaling", "count_claims"};
// What each renderer builds per scene (scene_changes.h) and the memory estimate
// (memory_estimate.h), likewise.
const std::vector<std::string> kBuildAndMemoryKeys = {"builds", "scene_changes", "memory"};
const std::vector<std::string> kPointKeys = {
    "renderer", "scene", "scene_n", "n",      "width",        "height", "pixels",
    "counters", "runs",  "seconds", "median", "relative_mad", "busy",   "effect_errors"};
const std::vector<std::string> kEffectErrorKeys = {"effect", "pixels", "rmse", "psnr_db", "ssim"};
const std::vector<std::string> kRunKeys = {"session", "prepare_seconds", "seconds", "order",
                                           "phases",  "reference_ratio", "busy"};
const std::vector<std::string> kSystemKeys = {"at",         "known", "cpus", "load",
                                              "other_busy", "steal", "mhz",  "governor"};

// A family is a built-in (its axis fixed) or a file grown by copies (axis "triangles").
void read_scenes(const Fields& top, StudyResult& r) {
  const json& scenes = top.array("scenes");
  if (scenes.empty()) fail("scenes", "must name at least one family");
  for (size_t i = 0; i < scenes.size(); ++i) {
    Fields s(scenes[i], index_path("scenes", i), {"name", "axis"});
    const std::string& name = s.string("name");
    const std::string& axis = s.string("axis");
    if (name.empty()) fail(s.path("name"), "must not be empty");
    Expected<Family> builtin = find_family("builtin:" + name);
    std::string want = builtin ? builtin->axis : "triangles";
    if (axis != want)
      fail(s.path("axis"),
           fmt::format("must be \"{}\" for {}, got {}", want, name, describe(s.at("axis"))));
    if (r.axes.count(name)) fail(s.path("name"), "names a family already listed");
    r.scenes.push_back(name);
    r.axes[name] = axis;
  }
}

void read_renderers(const Fields& top, StudyResult& r) {
  const json& names = top.array("renderer_order");
  if (names.empty()) fail("renderer_order", "must name at least one renderer");
  for (size_t i = 0; i < names.size(); ++i) {
    std::string path = index_path("renderer_order", i);
    if (!names[i].is_string()) fail(path, "must be a string, got " + describe(names[i]));
    const std::string& name = names[i].get_ref<const std::string&>();
    if (Expected<RendererChoice> c = find_renderer_choice(name); !c) fail(path, c.error().message);
    if (std::count(r.renderers.begin(), r.renderers.end(), name))
      fail(path, "names a renderer already listed");
    r.renderers.push_back(name);
  }
}

void read_machine(const Fields& top, StudyResult& r) {
  Fields m(top.at("machine"), "machine", {"cpu", "threads", "kernels", "versions"});
  r.machine.cpu = m.string("cpu");
  r.machine.threads = unsigned(m.whole("threads", 0, std::numeric_limits<unsigned>::max()));
  r.machine.kernels = m.string("kernels");
  for (const auto& item : m.object("versions").items()) {
    if (!item.value().is_string())
      fail(key_path("machine.versions", item.key()),
           "must be a string, got " + describe(item.value()));
    r.machine.versions[item.key()] = item.value().get<std::string>();
  }
}

SystemSnapshot read_system(const json& v, const std::string& path) {
  Fields f(v, path, kSystemKeys);
  SystemSnapshot s;
  s.at = f.number_or_nan("at");
  s.known = f.boolean("known");
  s.cpus = int(f.whole("cpus", 0, 1u << 20));
  const json& load = f.array("load");
  if (load.size() != 3) fail(f.path("load"), "must hold 3 load averages, got " + describe(load));
  double* loads[] = {&s.load1, &s.load5, &s.load15};
  for (size_t k = 0; k < 3; ++k)
    *loads[k] =
        load[k].is_null() ? 0.0 : Fields::number_at(load[k], index_path(f.path("load"), k), 0);
  s.other_busy = f.number_or_nan("other_busy");
  s.steal = f.number_or_nan("steal");
  if (!f.at("mhz").is_null()) s.mhz = f.number("mhz", 0);
  if (!f.at("governor").is_null()) s.governor = f.string("governor");
  return s;
}

void read_sessions(const Fields& top, StudyResult& r) {
  const json& sessions = top.array("sessions");
  for (size_t i = 0; i < sessions.size(); ++i) {
    const std::string path = index_path("sessions", i);
    Fields f(sessions[i], path, {"kind", "study", "system"});
    SessionInfo s;
    s.kind = f.string("kind");
    if (s.kind != "process" && s.kind != "preparation")
      fail(f.path("kind"), "must be \"process\" or \"preparation\", got " + describe(f.at("kind")));
    s.study = f.string("study");
    s.system = read_system(f.at("system"), f.path("system"));
    r.sessions.push_back(s);
  }
}

std::vector<std::string> strings_of(const Fields& top, const char* key) {
  const json& list = top.array(key);
  std::vector<std::string> out;
  for (size_t i = 0; i < list.size(); ++i) {
    if (!list[i].is_string())
      fail(index_path(key, i), "must be a string, got " + describe(list[i]));
    out.push_back(list[i].get<std::string>());
  }
  return out;
}

void read_request(const Fields& top, StudyResult& r) {
  if (top.string("format") != kStudyFormat)
    fail("format", fmt::format("must be \"{}\", got {}", kStudyFormat, describe(top.at("format"))));
  r.command = top.string("command");
  read_scenes(top, r);
  read_renderers(top, r);
  r.width = int(top.whole("width", 16, 16384));
  r.height = int(top.whole("height", 1, 1u << 20));
  r.mode = top.string("mode");
  if (r.mode != "visibility" && r.mode != "local" && r.mode != "full")
    fail("mode", "must be visibility, local or full, got " + describe(top.at("mode")));
  r.budget_seconds = top.number("budget_seconds", 0);
  if (!(r.budget_seconds > 0)) fail("budget_seconds", "must be > 0");
  r.elapsed_seconds = top.number_or_nan("elapsed_seconds");
  r.repetitions = int(top.whole("repetitions", 1, 1u << 20));
  r.sessions_per_point = int(top.whole("sessions_per_point", 1, 1u << 20));
  r.noise_threshold = top.number("noise_threshold", 0);
  if (!(r.noise_threshold < 1)) fail("noise_threshold", "must be below 1");
  r.seed = top.whole("seed", 0, std::numeric_limits<uint64_t>::max());
  r.run_id = top.string("run_id");
  if (r.run_id.empty()) fail("run_id", "must not be empty");
  r.merged_runs = strings_of(top, "merged_runs");
  r.bootstrap_replicates = int(top.whole("bootstrap_replicates", 1, 1u << 24));
  read_machine(top, r);
  r.system_before = read_system(top.at("system_before"), "system_before");
  r.system_after = read_system(top.at("system_after"), "system_after");
  read_sessions(top, r);
  const json& notes = top.array("notes");
  for (size_t i = 0; i < notes.size(); ++i) {
    if (!notes[i].is_string())
      fail(index_path("notes", i), "must be a string, got " + describe(notes[i]));
    if (!is_conclusion_note(notes[i].get<std::string>()))
      r.notes.push_back(notes[i].get<std::string>());
  }
  r.interrupted = top.boolean("interrupted");
  // Studies written before --shard have no "shard": they measured every point.
  if (top.has("shard") && !top.at("shard").is_null()) {
    Fields s(top.at("shard"), "shard", {"index", "count"});
    Shard shard{size_t(s.whole("index", 0, 1u << 20)), size_t(s.whole("count", 1, 1u << 20))};
    if (shard.index >= shard.count)
      fail("shard.index", fmt::format("must be below shard.count ({})", shard.count));
    r.shard = shard;
  }
}

// The conclusions are computed again from the points: only their type is checked.
void check_conclusions(const Fields& top) {
  top.object("renderers");
  // Prediction checks tested the crossovers of the study as it was: not carried to one
  // concluded again, and neither are the points they measured.
  for (const char* key : {"comparisons", "crossovers", "dominance", "scaling", "costs", "checks",
                          "splits", "check_points"})
    top.array(key);
  // Studies written before the counted-work models have none of these.
  for (const std::string& key : kCountedWorkKeys)
    if (top.has(key.c_str())) top.array(key.c_str());
  // The memory estimate was the sweep's: not carried to a study concluded again.
  for (const std::string& key : kBuildAndMemoryKeys)
    if (top.has(key.c_str())) top.array(key.c_str());
  if (!top.at("no_conclusion").is_null()) top.string("no_conclusion");
}

std::vector<double> seconds_of(const json& values, const std::string& path) {
  if (!values.is_array() || values.empty())
    fail(path, "must be an array of at least one time, got " + describe(values));
  std::vector<double> out;
  for (size_t k = 0; k < values.size(); ++k)
    out.push_back(Fields::number_at(values[k], index_path(path, k), 0));
  return out;
}

Run read_run(const json& v, const std::string& path, const StudyResult& r) {
  Fields f(v, path, kRunKeys);
  Run run;
  run.session = int(f.whole("session", 0, 1u << 30));
  if (size_t(run.session) >= r.sessions.size())
    fail(f.path("session"), fmt::format("must index sessions (0 .. {}), got {}",
                                        int(r.sessions.size()) - 1, run.session));
  run.prepare_seconds = f.number("prepare_seconds", 0);
  run.seconds = seconds_of(f.at("seconds"), f.path("seconds"));
  const json& order = f.array("order");
  if (order.size() != run.seconds.size())
    fail(f.path("order"), fmt::format("must have one entry per round ({}), got {}",
                                      run.seconds.size(), order.size()));
  for (size_t k = 0; k < order.size(); ++k)
    run.order.push_back(
        int(Fields::whole_at(order[k], index_path(f.path("order"), k), 0, 1u << 20)));
  for (const auto& item : f.object("phases").items()) {
    const std::string where = f.path("phases") + "." + item.key();
    run.phases[item.key()] = seconds_of(item.value(), where);
    if (run.phases[item.key()].size() != run.seconds.size())
      fail(where, fmt::format("must have one entry per round ({}), got {}", run.seconds.size(),
                              run.phases[item.key()].size()));
  }
  run.reference_ratio = f.number_or_nan("reference_ratio");
  run.busy = f.boolean("busy");
  return run;
}

// An identical frame's PSNR, infinite, is written as null.
PointEffectError read_effect_error(const json& v, const std::string& path) {
  Fields f(v, path, kEffectErrorKeys);
  PointEffectError e;
  e.effect = f.string("effect");
  e.pixels = f.number("pixels", 1);
  e.rmse = f.number("rmse", 0);
  e.psnr_db = f.at("psnr_db").is_null()
                  ? std::numeric_limits<double>::infinity()
                  : f.number("psnr_db", -std::numeric_limits<double>::infinity());
  e.ssim = f.number("ssim", -1);
  if (e.ssim > 1) fail(f.path("ssim"), fmt::format("must be <= 1, got {}", e.ssim));
  return e;
}

Measurement read_point(const json& v, const std::string& path, const StudyResult& r) {
  Fields p(v, path, kPointKeys);
  Measurement m;
  m.renderer = p.string("renderer");
  if (!std::count(r.renderers.begin(), r.renderers.end(), m.renderer))
    fail(p.path("renderer"), describe(p.at("renderer")) + " is not in renderer_order");
  m.scene = p.string("scene");
  if (!r.axes.count(m.scene)) fail(p.path("scene"), describe(p.at("scene")) + " is not in scenes");
  m.scene_n = p.number("scene_n", 1);
  m.n = p.number("n", 0);
  m.width = int(p.whole("width", 1, 1u << 20));
  m.height = int(p.whole("height", 1, 1u << 20));
  m.pixels = p.number("pixels", 0);
  if (!(m.pixels > 0)) fail(p.path("pixels"), "must be > 0");
  for (const auto& item : p.object("counters").items())
    m.counters[item.key()] =
        Fields::number_at(item.value(), p.path("counters") + "." + item.key(), 0);
  if (p.has("effect_errors")) {
    const json& errors = p.array("effect_errors");
    for (size_t k = 0; k < errors.size(); ++k)
      m.effect_errors.push_back(
          read_effect_error(errors[k], index_path(p.path("effect_errors"), k)));
  }
  const json& runs = p.array("runs");
  if (runs.empty()) fail(p.path("runs"), "must hold at least one run");
  for (size_t k = 0; k < runs.size(); ++k) {
    m.runs.push_back(read_run(runs[k], index_path(p.path("runs"), k), r));
    for (size_t j = 0; j < k; ++j)
      if (m.runs[j].session == m.runs[k].session)
        fail(index_path(p.path("runs"), k) + ".session",
             fmt::format("session {} already has a run at this point", m.runs[k].session));
  }
  for (const char* derived : {"seconds", "median", "relative_mad", "busy"}) p.at(derived);
  return m;
}

StudyResult read_study(const json& doc) {
  std::vector<std::string> top_keys = kTopKeys;
  top_keys.insert(top_keys.end(), kCountedWorkKeys.begin(), kCountedWorkKeys.end());
  top_keys.insert(top_keys.end(), kBuildAndMemoryKeys.begin(), kBuildAndMemoryKeys.end());
  Fields top(doc, "", top_keys);
  StudyResult r;
  read_request(top, r);
  check_conclusions(top);
  const json& points = top.array("points");
  for (size_t i = 0; i < points.size(); ++i)
    r.points.push_back(read_point(points[i], index_path("points", i), r));
  return r;
}

}  // namespace

Expected<StudyResult> read_study_json(const std::string& text, const std::string& path) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    return bad_input(fmt::format("{}: JSON syntax: {}", path, e.what()));
  }
  try {
    return read_study(doc);
  } catch (const ReadError& e) {
    return bad_input(
        fmt::format("{}: {}: {}", path, e.path.empty() ? "top level" : e.path, e.what));
  }
}

Expected<StudyResult> load_study_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return bad_input(path + ": cannot be read (is it a study folder written by rvr study?)");
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) return bad_input(path + ": read error");
  return read_study_json(text.str(), path);
}

}  // namespace rvr::study
