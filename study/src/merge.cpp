// Pooling studies by machine type and comparing machine types (see merge.h).
#include "rvr/study/merge.h"

#include <fmt/format.h>
#include <stddef.h>
#include <stdint.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <compare>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <tuple>
#include <type_traits>
#include <utility>

#include "rvr/study/bootstrap.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/crossover.h"
#include "rvr/study/measurement.h"
#include "rvr/study/study_markdown.h"
#include "rvr/study/sweep_plan.h"
#include "rvr/study/system_probe.h"

namespace rvr::study {
namespace {

// What makes two studies poolable: the machine type and the mode.
using GroupKey = std::tuple<std::string, unsigned, std::string, std::string>;

GroupKey key_of(const StudyResult& s) {
  return {s.machine.cpu, s.machine.threads, s.machine.kernels, s.mode};
}

// Lower-case letters and digits, every other run of characters one '-'.
std::string slug_words(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c)))
      out += char(std::tolower(static_cast<unsigned char>(c)));
    else if (!out.empty() && out.back() != '-')
      out += '-';
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out;
}

std::string slug_of(const StudyResult& s) {
  std::string kernels = s.machine.kernels.substr(0, s.machine.kernels.find(' '));
  return fmt::format("{}-{}t-{}-{}", slug_words(s.machine.cpu), s.machine.threads,
                     slug_words(kernels), slug_words(s.mode));
}

std::string join(const std::vector<std::string>& words, const char* sep = ", ") {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : sep) + w;
  return out;
}

void add_unique(std::vector<std::string>& list, const std::string& item) {
  if (std::find(list.begin(), list.end(), item) == list.end()) list.push_back(item);
}

size_t index_in(const std::vector<std::string>& list, const std::string& item) {
  return size_t(std::find(list.begin(), list.end(), item) - list.begin());
}

// Unites the points of the group's studies: each study's sessions are the merged study's too
// (renumbered), so a point measured by several keeps the runs of each as runs of its own, the
// level where the variation between them arises. A study already held (its run id, or a study
// merged into it) is refused, and so is a run whose frames are another's to the last digit.
class PointPool {
 public:
  Status add(const StudySource& source, StudyResult& merged) {
    const StudyResult& s = source.study;
    std::vector<std::string> runs = s.merged_runs;
    runs.push_back(s.run_id);
    for (const std::string& id : runs) {
      auto [it, fresh] = run_sources_.try_emplace(id, source.name);
      if (!fresh)
        return bad_input(fmt::format(
            "{}: holds the measurements of study {}, already merged from {}: a study is merged "
            "once (is one a merged copy of the other?)",
            source.name, id, it->second));
      merged.merged_runs.push_back(id);
    }
    const int offset = int(merged.sessions.size());
    for (const SessionInfo& info : s.sessions) merged.sessions.push_back(info);
    for (const Measurement& m : s.points) {
      auto key = std::make_tuple(m.renderer, m.scene, m.scene_n, m.width);
      auto [it, fresh] = index_.try_emplace(key, points_.size());
      if (fresh) {
        points_.push_back(m);
        points_.back().runs.clear();
        first_source_.push_back(source.name);
      }
      Measurement& pooled = points_[it->second];
      if (pooled.n != m.n || pooled.pixels != m.pixels)
        return bad_input(fmt::format(
            "{}: {} on {}:{} at width {} has n {} and {} pixels, but {} in {} and {} pixels: "
            "not the same point",
            source.name, m.renderer, m.scene, m.scene_n, m.width, m.n, m.pixels, pooled.n,
            first_source_[it->second], pooled.pixels));
      repeated_ = repeated_ || !fresh;
      for (const Run& run : m.runs) {
        for (const Run& held : pooled.runs)
          if (held.seconds == run.seconds)
            return bad_input(fmt::format(
                "{}: {} on {}:{} at width {} has a run whose frame times are those of a run "
                "already merged from {}: the same measurement twice",
                source.name, m.renderer, m.scene, m.scene_n, m.width, first_source_[it->second]));
        pooled.runs.push_back(run);
        pooled.runs.back().session += offset;
      }
      if (pooled.counters.empty()) pooled.counters = m.counters;
      if (pooled.effect_errors.empty()) pooled.effect_errors = m.effect_errors;
    }
    return ok_status();
  }

  bool repeated() const { return repeated_; }

  // By family, N, width and renderer, in the study's orders of families and renderers.
  std::vector<Measurement> sorted(const StudyResult& r) const {
    std::vector<Measurement> out = points_;
    auto rank = [&](const Measurement& m) {
      return std::make_tuple(index_in(r.scenes, m.scene), m.scene_n, m.width,
                             index_in(r.renderers, m.renderer));
    };
    std::stable_sort(out.begin(), out.end(),
                     [&](const Measurement& a, const Measurement& b) { return rank(a) < rank(b); });
    return out;
  }

 private:
  std::map<std::tuple<std::string, std::string, double, int>, size_t> index_;
  std::vector<Measurement> points_;
  std::vector<std::string> first_source_;
  std::map<std::string, std::string> run_sources_;  // run id -> the source that held it
  bool repeated_ = false;
};

// Which shards of which count the sources are; a note for each count whose shards are not all
// there.
std::vector<std::string> shard_notes(const std::vector<const StudySource*>& sources) {
  std::map<size_t, std::set<size_t>> present;  // count -> indices
  for (const StudySource* s : sources)
    if (s->study.shard) present[s->study.shard->count].insert(s->study.shard->index);
  std::vector<std::string> notes;
  for (const auto& [count, indices] : present) {
    std::vector<std::string> missing;
    for (size_t i = 0; i < count; ++i)
      if (!indices.count(i)) missing.push_back(std::to_string(i));
    if (!missing.empty())
      notes.push_back(fmt::format("shard{} {} of {} missing: their points were not measured",
                                  missing.size() > 1 ? "s" : "", join(missing), count));
  }
  if (present.size() > 1) notes.push_back("shards of different counts were merged");
  return notes;
}

// Each source's notes, a note given by several once, naming them.
std::vector<std::string> source_notes(const std::vector<const StudySource*>& sources) {
  std::vector<std::string> order;
  std::map<std::string, std::vector<std::string>> by_note;
  for (const StudySource* s : sources)
    for (const std::string& note : s->study.notes) {
      add_unique(order, note);
      by_note[note].push_back(s->name);
    }
  std::vector<std::string> out;
  out.reserve(order.size());
  for (const std::string& note : order) out.push_back(join(by_note[note]) + ": " + note);
  return out;
}

// The group's request fields from its first study, with the others' renderers and families
// added; image sizes must agree.
Status pool_request(const std::vector<const StudySource*>& sources, StudyResult& r) {
  const StudyResult& first = sources[0]->study;
  r.width = first.width, r.height = first.height;
  r.mode = first.mode;
  r.repetitions = first.repetitions;
  r.sessions_per_point = first.sessions_per_point;
  r.noise_threshold = first.noise_threshold;
  r.seed = first.seed;
  r.bootstrap_replicates = first.bootstrap_replicates;
  r.machine = first.machine;
  for (const StudySource* s : sources) {
    const StudyResult& study = s->study;
    if (study.width != first.width || study.height != first.height)
      return bad_input(fmt::format(
          "{}: {}×{}, but {} (same machine type and mode) is {}×{}: studies pooled must have "
          "one image size",
          s->name, study.width, study.height, sources[0]->name, first.width, first.height));
    for (const std::string& scene : study.scenes) {
      add_unique(r.scenes, scene);
      r.axes[scene] = study.axes.at(scene);
    }
    for (const std::string& name : study.renderers) add_unique(r.renderers, name);
    r.budget_seconds += study.budget_seconds;
    if (std::isfinite(study.elapsed_seconds)) r.elapsed_seconds += study.elapsed_seconds;
    r.interrupted = r.interrupted || study.interrupted;
    if (study.noise_threshold != first.noise_threshold)
      return bad_input(fmt::format(
          "{}: noise threshold {}, but {} has {}: studies pooled must judge their points alike",
          s->name, study.noise_threshold, sources[0]->name, first.noise_threshold));
  }
  r.system_before = first.system_before;
  r.system_after = sources.back()->study.system_after;
  return ok_status();
}

// The run id of a merged study: a hash (FNV-1a) of the run ids it holds, so that merging the same
// studies gives the same id.
std::string merged_run_id(const std::vector<std::string>& runs) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (const std::string& id : runs)
    for (char c : id + ";") h = (h ^ uint64_t(static_cast<unsigned char>(c))) * 0x100000001b3ull;
  return fmt::format("merged-{:016x}", h);
}

Expected<StudyResult> pool(const std::vector<const StudySource*>& sources) {
  StudyResult r;
  RVR_TRY(pool_request(sources, r));
  PointPool points;
  for (const StudySource* s : sources) RVR_TRY(points.add(*s, r));
  r.run_id = merged_run_id(r.merged_runs);
  r.points = points.sorted(r);
  std::vector<std::string> names;
  names.reserve(sources.size());
  for (const StudySource* s : sources) names.push_back(s->name);
  r.notes.push_back(fmt::format("merged from {} stud{}: {}", sources.size(),
                                sources.size() > 1 ? "ies" : "y", join(names)));
  if (points.repeated())
    r.notes.push_back(
        "points measured by more than one study hold the runs of each, each run one session");
  for (const std::string& note : shard_notes(sources)) r.notes.push_back(note);
  for (const std::string& note : source_notes(sources)) r.notes.push_back(note);
  conclude(r, BootstrapOptions{r.bootstrap_replicates, r.seed});
  return r;
}

}  // namespace

Expected<std::vector<MachineGroup>> merge_studies(const std::vector<StudySource>& sources) {
  if (sources.empty()) return bad_input("--merge: no study given");
  std::vector<GroupKey> keys;
  std::map<GroupKey, std::vector<const StudySource*>> members;
  for (const StudySource& s : sources) {
    GroupKey key = key_of(s.study);
    if (!members.count(key)) keys.push_back(key);
    members[key].push_back(&s);
  }
  std::vector<MachineGroup> groups;
  std::set<std::string> slugs;
  for (const GroupKey& key : keys) {
    const std::vector<const StudySource*>& group = members[key];
    RVR_TRY_ASSIGN(study, pool(group));
    MachineGroup g;
    const MachineInfo& m = study->machine;
    g.label = fmt::format("{}, {} threads, kernels {}, {} mode", m.cpu, m.threads, m.kernels,
                          study->mode);
    g.slug = slug_of(*study);
    for (int k = 2; slugs.count(g.slug); ++k) g.slug = fmt::format("{}-{}", slug_of(*study), k);
    slugs.insert(g.slug);
    for (const StudySource* s : group) g.sources.push_back(s->name);
    g.study = std::move(*study);
    groups.push_back(std::move(g));
  }
  return groups;
}

namespace {

// A pair of renderers compared on one family along one axis (the pixel axis at one N), the pair
// in name order.
using PairKey = std::tuple<std::string, std::string, double, std::string, std::string>;

PairKey pair_key(const std::string& a, const std::string& b, const std::string& scene,
                 const std::string& axis, double n) {
  return {scene, axis, n, std::min(a, b), std::max(a, b)};
}

std::string crossover_text(const Crossover& c) {
  if (!c.measured)
    return fmt::format("crossover {} (extrapolated, outside {}–{})", format_number(c.value),
                       format_number(c.range_low), format_number(c.range_high));
  auto end = [](double v, const char* beyond) {
    return std::isinf(v) ? std::string(beyond) : format_number(v);
  };
  return fmt::format("crossover {} ({}–{}){}", format_number(c.value),
                     end(c.ci95.low, "below range"), end(c.ci95.high, "above range"),
                     c.contradicted ? ", contradicted by its check" : "");
}

std::string dominance_text(const Dominance& d) {
  return fmt::format("{} faster where significant: {} of {} points, {}–{} (≥ {:.2f}×)", d.faster,
                     d.significant, d.points, format_number(d.significant_low),
                     format_number(d.significant_high), d.min_ratio);
}

}  // namespace

std::string comparison_markdown(const std::vector<MachineGroup>& groups) {
  std::vector<PairKey> rows;
  std::map<PairKey, std::vector<std::string>> cells;  // one per group
  auto cell = [&](const PairKey& key, size_t group, const std::string& text) {
    if (!cells.count(key)) rows.push_back(key), cells[key].resize(groups.size());
    std::string& c = cells[key][group];
    c += (c.empty() ? "" : "; ") + text;
  };
  for (size_t g = 0; g < groups.size(); ++g) {
    for (const Crossover& c : groups[g].study.crossovers)
      cell(pair_key(c.a, c.b, c.scene, c.axis, c.n), g, crossover_text(c));
    for (const Dominance& d : groups[g].study.dominance)
      cell(pair_key(d.faster, d.slower, d.scene, d.axis, d.n), g, dominance_text(d));
  }
  std::string text = "# rvr study: machine types compared\n\n";
  text +=
      "Studies from different machine types (CPU, threads, SIMD kernels) or modes are never "
      "pooled: each column is one machine type's study, concluded from its own points. "
      "Crossovers are given with their 95% interval.\n\n";
  for (size_t g = 0; g < groups.size(); ++g)
    text += fmt::format("{}. {} ({}×{}; {} points from {}): `{}/`\n", g + 1, groups[g].label,
                        groups[g].study.width, groups[g].study.height,
                        groups[g].study.points.size(), join(groups[g].sources), groups[g].slug);
  text += "\n| family | renderers | axis |";
  for (size_t g = 0; g < groups.size(); ++g) text += fmt::format(" {} |", g + 1);
  text += "\n|---|---|---|";
  for (size_t g = 0; g < groups.size(); ++g) text += "---|";
  text += "\n";
  for (const PairKey& key : rows) {
    const auto& [scene, axis, n, a, b] = key;
    std::string along = n > 0 ? fmt::format("{} at N = {}", axis, format_number(n)) : axis;
    text += fmt::format("| {} | {} vs {} | {} |", scene, a, b, along);
    for (const std::string& c : cells[key]) text += " " + (c.empty() ? "not compared" : c) + " |";
    text += "\n";
  }
  if (rows.empty()) text += "\nNo pair of loop orders was compared on any machine type.\n";
  return text;
}

}  // namespace rvr::study
