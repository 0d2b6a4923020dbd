// What each renderer builds per scene and the frames per scene change that pay for it (see
// scene_changes.h).
#include "rvr/study/scene_changes.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <type_traits>
#include <utility>

#include "rvr/core/check.h"
#include "rvr/present/html_escape.h"
#include "rvr/present/powers_of_ten.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/study.h"
#include "rvr/study/study_markdown.h"
#include "scene_changes_html.h"

namespace rvr::study {
namespace {

using present::escape_html;
using present::html_with_powers;

constexpr double kInf = std::numeric_limits<double>::infinity();

// a's and b's runs of the sessions both measured: the quiet ones where both have some, else all.
std::vector<std::pair<const Run*, const Run*>> paired_runs(const Measurement& a,
                                                           const Measurement& b) {
  auto pair_up = [](const std::vector<const Run*>& ra, const std::vector<const Run*>& rb) {
    std::vector<std::pair<const Run*, const Run*>> out;
    for (const Run* x : ra)
      for (const Run* y : rb)
        if (x->session == y->session && !x->seconds.empty() && !y->seconds.empty())
          out.push_back({x, y});
    return out;
  };
  std::vector<std::pair<const Run*, const Run*>> quiet = pair_up(timed_runs(a), timed_runs(b));
  if (!quiet.empty()) return quiet;
  std::vector<const Run*> all_a, all_b;
  for (const Run& r : a.runs) all_a.push_back(&r);
  for (const Run& r : b.runs) all_b.push_back(&r);
  return pair_up(all_a, all_b);
}

// Frame times (geometric mean of the runs' Harrell–Davis medians) and preparations (mean over
// the runs) of a and b over the sessions `drawn` (indexes into `runs`), each run's rounds drawn
// by `rounds` (the same for a and b; empty: every round as measured).
struct PairTimes {
  double frame_a = 0, frame_b = 0, prepare_a = 0, prepare_b = 0;
};

PairTimes pair_times(const std::vector<std::pair<const Run*, const Run*>>& runs,
                     const std::vector<size_t>& drawn,
                     const std::vector<std::vector<size_t>>& rounds) {
  PairTimes t;
  double log_a = 0, log_b = 0;
  std::vector<double> xa, xb;
  for (size_t k = 0; k < drawn.size(); ++k) {
    const auto& [ra, rb] = runs[drawn[k]];
    xa.clear();
    xb.clear();
    if (rounds.empty()) {
      xa = ra->seconds;
      xb = rb->seconds;
    } else {
      for (size_t i : rounds[k]) xa.push_back(ra->seconds[i]), xb.push_back(rb->seconds[i]);
    }
    log_a += std::log(hd_median(xa));
    log_b += std::log(hd_median(xb));
    t.prepare_a += ra->prepare_seconds;
    t.prepare_b += rb->prepare_seconds;
  }
  const double s = double(drawn.size());
  t.frame_a = std::exp(log_a / s);
  t.frame_b = std::exp(log_b / s);
  t.prepare_a /= s;
  t.prepare_b /= s;
  return t;
}

double frames_of(const PairTimes& t) {
  return frames_per_scene_change(t.frame_a, t.prepare_a, t.frame_b, t.prepare_b);
}

// The points at the study's full image size, by renderer and scene.
std::vector<const Measurement*> full_size(const StudyResult& r, const std::string& renderer,
                                          const std::string& scene) {
  std::vector<const Measurement*> out;
  for (const Measurement& m : r.points)
    if (m.renderer == renderer && m.scene == scene && !m.runs.empty() &&
        m.pixels == double(r.width) * double(r.height))
      out.push_back(&m);
  std::sort(out.begin(), out.end(),
            [](const Measurement* x, const Measurement* y) { return x->n < y->n; });
  return out;
}

bool builds_nothing(const std::string& renderer) {
  return model_form_of(renderer) == ModelForm::ZBuffer;
}

// "31 (95%: 25 – 40)", with "never" for an infinite end.
std::string frames_text(double k, const Interval& ci) {
  auto one = [](double v) { return std::isinf(v) ? std::string("never") : format_number(v); };
  return fmt::format("{} (95%: {} – {})", one(k), one(ci.low), one(ci.high));
}

// "88–3.2×10^5", or one value.
std::string range_text(double from, double to) {
  return from == to ? format_number(from)
                    : fmt::format("{}–{}", format_number(from), format_number(to));
}

std::string seconds_text(double s) {
  if (s >= 1) return fmt::format("{} s", format_number(s));
  if (s >= 1e-3) return fmt::format("{} ms", format_number(1e3 * s));
  return fmt::format("{} µs", format_number(1e6 * s));
}

// One renderer's preparation on one scene, in words.
std::string build_sentence(const StudyResult& r, const std::string& renderer,
                           const std::string& scene) {
  std::vector<const BuildCost*> costs;
  for (const BuildCost& b : r.builds)
    if (b.renderer == renderer && b.scene == scene) costs.push_back(&b);
  if (costs.empty()) return "";
  const BuildCost &lo = *costs.front(), &hi = *costs.back();
  double slowest = 0;
  for (const BuildCost* b : costs) slowest = std::max(slowest, b->high);
  if (builds_nothing(renderer))
    return fmt::format(
        "{} on {} builds nothing per scene: its preparation (the renderer made) took at most {} "
        "at any N; it transforms and sets up every triangle again in every frame, inside its "
        "frame time.",
        renderer, scene, seconds_text(slowest));
  const std::string& axis = r.axes.at(scene);
  const std::string per_triangle =
      axis == "triangles" ? fmt::format("{} ns per triangle; ", format_number(hi.ns_per_triangle))
                          : "";
  return fmt::format(
      "{} on {} builds its BVH per scene in {} at {} {} and {} at {} ({}the median of {} runs, "
      "each a fresh preparation; slowest run {}).",
      renderer, scene, seconds_text(lo.prepare_seconds), format_number(lo.n), axis,
      seconds_text(hi.prepare_seconds), format_number(hi.n), per_triangle, hi.runs,
      seconds_text(hi.high));
}

// Where k* falls along N for one pair on one scene.
std::string pair_sentence(const StudyResult& r, const std::string& a, const std::string& b,
                          const std::string& scene) {
  std::vector<const SceneChange*> along;  // the points with a session both measured in
  for (const SceneChange& c : r.scene_changes)
    if (c.a == a && c.b == b && c.scene == scene && !std::isnan(c.frames)) along.push_back(&c);
  if (along.empty()) return "";
  std::vector<const SceneChange*> finite;
  for (const SceneChange* c : along)
    if (std::isfinite(c->frames)) finite.push_back(c);
  if (finite.empty())
    return fmt::format(
        "On {}, {}'s frames are nowhere faster than {}'s ({}–{} {}): {} costs less per frame "
        "however seldom the scene changes.",
        scene, b, a, format_number(along.front()->n), format_number(along.back()->n),
        r.axes.at(scene), a);
  std::vector<std::string> at;
  const size_t shown = std::min<size_t>(finite.size(), 4);
  for (size_t i = finite.size() - shown; i < finite.size(); ++i)
    at.push_back(fmt::format("{} at {}", frames_text(finite[i]->frames, finite[i]->ci95),
                             format_number(finite[i]->n)));
  std::string list;
  for (const std::string& s : at) list += (list.empty() ? "" : ", ") + s;
  // Where b wins even a scene rebuilt every frame (k* <= 1): not always one stretch of N.
  std::vector<const SceneChange*> every_frame;
  for (const SceneChange* c : along)
    if (c->frames <= 1) every_frame.push_back(c);
  const std::string rebuilt =
      every_frame.empty()
          ? fmt::format(
                "a scene rebuilt every frame (k = 1) is cheaper with {} at every N measured", a)
          : fmt::format("{} wins even a scene rebuilt every frame at {} of them ({} {})", b,
                        every_frame.size(),
                        range_text(every_frame.front()->n, every_frame.back()->n),
                        r.axes.at(scene));
  return fmt::format(
      "On {}, where {}'s frames are faster than {}'s ({} of {} points, {} {}), a scene that "
      "changes every k frames costs less with {} only above k = {}; {}.",
      scene, b, a, finite.size(), along.size(), range_text(finite.front()->n, finite.back()->n),
      r.axes.at(scene), b, list, rebuilt);
}

}  // namespace

double frames_per_scene_change(double frame_a, double prepare_a, double frame_b, double prepare_b) {
  if (!(frame_a > frame_b)) return kInf;
  return std::max(0.0, (prepare_b - prepare_a) / (frame_a - frame_b));
}

BuildCost build_cost(const Measurement& m) {
  BuildCost b;
  b.renderer = m.renderer;
  b.scene = m.scene;
  b.n = m.n;
  b.pixels = m.pixels;
  std::vector<double> prepare;
  for (const Run& run : m.runs) prepare.push_back(run.prepare_seconds);
  b.runs = prepare.size();
  if (prepare.empty()) return b;
  b.prepare_seconds = median(prepare);
  b.low = *std::min_element(prepare.begin(), prepare.end());
  b.high = *std::max_element(prepare.begin(), prepare.end());
  b.ns_per_triangle = m.n > 0 ? 1e9 * b.prepare_seconds / m.n : 0;
  return b;
}

SceneChange scene_change(const Measurement& a, const Measurement& b, const BootstrapOptions& boot) {
  RVR_CHECK(a.scene == b.scene && a.scene_n == b.scene_n && a.pixels == b.pixels,
            "a scene change compares two renderers at one point: ", a.scene, " ", a.scene_n,
            " and ", b.scene, " ", b.scene_n);
  SceneChange c;
  c.a = a.renderer;
  c.b = b.renderer;
  c.scene = a.scene;
  c.n = a.n;
  c.pixels = a.pixels;
  const std::vector<std::pair<const Run*, const Run*>> runs = paired_runs(a, b);
  if (runs.empty()) {
    c.frames = c.ci95.low = c.ci95.high = std::numeric_limits<double>::quiet_NaN();
    return c;
  }
  std::vector<size_t> every(runs.size());
  for (size_t k = 0; k < runs.size(); ++k) every[k] = k;
  const PairTimes t = pair_times(runs, every, {});
  c.frame_a = t.frame_a;
  c.frame_b = t.frame_b;
  c.prepare_a = t.prepare_a;
  c.prepare_b = t.prepare_b;
  c.frames = frames_of(t);
  Rng rng(boot.seed);
  std::vector<double> replicates;
  replicates.reserve(size_t(boot.replicates));
  std::vector<size_t> drawn(runs.size());
  std::vector<std::vector<size_t>> rounds(runs.size());
  for (int i = 0; i < boot.replicates; ++i) {
    for (size_t k = 0; k < runs.size(); ++k) {
      drawn[k] = rng.below(runs.size());
      const auto& [ra, rb] = runs[drawn[k]];
      const size_t count = std::min(ra->seconds.size(), rb->seconds.size());
      rounds[k].resize(count);
      for (size_t& round : rounds[k]) round = rng.below(count);
    }
    replicates.push_back(frames_of(pair_times(runs, drawn, rounds)));
  }
  c.ci95 = percentile_interval(replicates);
  return c;
}

void scene_change_conclusions(StudyResult& r, const BootstrapOptions& boot) {
  for (const std::string& scene : r.scenes)
    for (const std::string& renderer : r.renderers)
      for (const Measurement* m : full_size(r, renderer, scene)) r.builds.push_back(build_cost(*m));
  for (const std::string& scene : r.scenes)
    for (const std::string& a : r.renderers) {
      if (!builds_nothing(a)) continue;
      for (const std::string& b : r.renderers) {
        if (builds_nothing(b)) continue;
        std::map<double, const Measurement*> of_b;
        for (const Measurement* m : full_size(r, b, scene)) of_b[m->scene_n] = m;
        for (const Measurement* m : full_size(r, a, scene))
          if (auto it = of_b.find(m->scene_n); it != of_b.end())
            r.scene_changes.push_back(scene_change(*m, *it->second, boot));
      }
    }
}

std::vector<std::string> build_sentences(const StudyResult& r) {
  std::vector<std::string> out;
  for (const std::string& scene : r.scenes) {
    for (const std::string& renderer : r.renderers)
      if (std::string s = build_sentence(r, renderer, scene); !s.empty()) out.push_back(s);
    std::set<std::pair<std::string, std::string>> pairs;
    for (const SceneChange& c : r.scene_changes)
      if (c.scene == scene && pairs.insert({c.a, c.b}).second)
        if (std::string s = pair_sentence(r, c.a, c.b, scene); !s.empty()) out.push_back(s);
  }
  return out;
}

std::string builds_html(const StudyResult& r, const std::string& scene) {
  std::map<double, std::map<std::string, const BuildCost*>> by_n;
  for (const BuildCost& b : r.builds)
    if (b.scene == scene) by_n[b.n][b.renderer] = &b;
  if (by_n.empty()) return "";
  std::vector<std::pair<std::string, std::string>> pairs;
  for (const SceneChange& c : r.scene_changes)
    if (c.scene == scene &&
        std::find(pairs.begin(), pairs.end(), std::pair{c.a, c.b}) == pairs.end())
      pairs.push_back({c.a, c.b});
  std::string o =
      "<h3>Building per scene</h3>\n<p>Each renderer's preparation for the scene (median over "
      "its runs, each a fresh preparation), and the frames a scene must last for a renderer "
      "that builds to cost less per frame than the z-buffer, which builds nothing: k* = "
      "(prepare<sub>b</sub> − prepare<sub>a</sub>) / (frame<sub>a</sub> − frame<sub>b</sub>), "
      "“never” where b's frames are no faster.</p>\n<div class=\"scroll\"><table "
      "class=\"builds\"><tr><th>" +
      escape_html(r.axes.at(scene)) + "</th>";
  for (const std::string& renderer : r.renderers) o += "<th>" + escape_html(renderer) + "</th>";
  for (const auto& [a, b] : pairs)
    o += fmt::format("<th>k*: {} over {}</th>", escape_html(b), escape_html(a));
  o += "</tr>\n";
  for (const auto& [n, costs] : by_n) {
    o += "<tr><td class=\"num\">" + html_with_powers(format_number(n)) + "</td>";
    for (const std::string& renderer : r.renderers) {
      auto it = costs.find(renderer);
      o += "<td class=\"num\">" +
           (it == costs.end() ? std::string("–")
                              : html_with_powers(seconds_text(it->second->prepare_seconds))) +
           "</td>";
    }
    for (const auto& [a, b] : pairs) {
      std::string cell = "–";
      for (const SceneChange& c : r.scene_changes)
        if (c.scene == scene && c.a == a && c.b == b && c.n == n && !std::isnan(c.frames))
          cell = html_with_powers(frames_text(c.frames, c.ci95));
      o += "<td class=\"num\">" + cell + "</td>";
    }
    o += "</tr>\n";
  }
  return o + "</table></div>\n";
}

}  // namespace rvr::study
