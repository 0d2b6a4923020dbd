// The study's sweep within its budget (see run_study.h).
#include "rvr/study/run_study.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <set>
#include <tuple>
#include <utility>

#include "rvr/renderers/registry.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/measurement.h"
#include "rvr/study/prediction_checks.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study {
namespace {

// Of the budget share of a scene, where the log-spaced sweep of N must end, and the sweep of
// the pixel count; the rest is for the points added near crossovers.
constexpr double kBaseShare = 0.6;
constexpr double kPixelShare = 0.8;
constexpr int kRefinementRounds = 3;
// How long one timing of the reference frame takes at least, in frames in a row.
constexpr double kReferenceSeconds = 2e-3;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

Status validate(const StudyRequest& r) {
  if (r.scenes.empty()) return bad_input("study: no scene family given");
  for (const std::string& s : r.scenes)
    if (Expected<Family> f = find_family(s); !f) return f.error();
  if (r.renderers.empty()) return bad_input("--renderers: no renderer given");
  for (const std::string& name : r.renderers)
    if (Expected<RendererChoice> c = find_renderer_choice(name); !c) return c.error();
  if (!(r.budget_seconds > 0) || !std::isfinite(r.budget_seconds))
    return bad_input(fmt::format("--budget: must be > 0 seconds, got {}", r.budget_seconds));
  if (r.width < 16 || r.width > 16384)
    return bad_input(fmt::format("--width: must be in 16 .. 16384, got {}", r.width));
  // Fewer, and the bootstrap's 95% intervals hold the truth only ~85% of the time (test_study).
  if (r.repetitions < 5)
    return bad_input(fmt::format("--repetitions: must be >= 5, got {}", r.repetitions));
  if (r.shard && (r.shard->count < 1 || r.shard->index >= r.shard->count))
    return bad_input(fmt::format("--shard: must be I/N with 0 <= I < N, got {}/{}", r.shard->index,
                                 r.shard->count));
  return ok_status();
}

// A point of a family in words: "N=1000", or "12 copies" of a file.
std::string point_name(const Family& family, size_t n) {
  return family.source.empty() ? fmt::format("N={}", n) : fmt::format("{} copies", n);
}

// The state of one running study.
class Sweep {
 public:
  Sweep(const StudyRequest& request, const StudyHooks& hooks, StudyResult& result)
      : request_(request), hooks_(hooks), result_(result), rng_(request.seed) {
    if (!hooks_.now) {
      hooks_.now = [] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
            .count();
      };
    }
    start_ = hooks_.now();
  }

  double elapsed() const { return hooks_.now() - start_; }
  bool cancelled() const { return hooks_.cancelled && hooks_.cancelled(); }

  Status run_scene(const Family& family, double share_end);

 private:
  // Measures (n, width) unless it was measured, or it would end past `limit` as predicted from
  // the points measured at the full width: false then.
  Expected<bool> try_point(const Family& family, size_t n, int width, double limit,
                           double share_end);
  Status measure(const Family& family, size_t n, int width, double deadline);
  void time_rounds(const Family& family, size_t n, FrameSource& frames, double deadline,
                   std::vector<Measurement>& points, Status& status);
  Status start_reference(const Family& family);
  Expected<double> time_reference();
  Status measure_busy_points_again(const Family& family, double share_end);
  Status sweep_n(const Family& family, double limit, double share_end);
  Status sweep_pixels(const Family& family, double limit, double share_end);
  std::vector<size_t> crossover_midpoints(const Family& family) const;
  bool in_this_shard(size_t n, int width) const;
  void progress(const std::string& what) const {
    if (hooks_.on_progress) hooks_.on_progress(what);
  }

  const StudyRequest& request_;
  StudyHooks hooks_;
  StudyResult& result_;
  Rng rng_;
  double start_ = 0;
  std::set<std::tuple<std::string, size_t, int>> measured_;  // family, n, width
  CostPredictor cost_;                      // of the current family's points at the full width
  std::unique_ptr<FrameSource> reference_;  // the current family's reference frame
  int reference_frames_ = 1;                // frames in a row per reference time
  double quickest_reference_ = kInfinity;   // its quickest time in the family so far
  double slowest_reference_ = 0;            // its slowest time while measuring one point
  std::vector<PlannedPoint> plan_;          // the current family's
  size_t plan_offset_ = 0;                  // the index of its first point in the study's plan
};

// The reference frame of a family: its smallest point at full width, the first renderer, run
// often enough in a row to take kReferenceSeconds (a frame of a few microseconds alone would
// measure the timer and the scheduler); its quickest time starts as the median of five.
Status Sweep::start_reference(const Family& family) {
  Expected<std::unique_ptr<FrameSource>> frames =
      hooks_.prepare(family, family.low, request_.width);
  if (!frames) return frames.error();
  reference_ = std::move(*frames);
  reference_frames_ = 1;
  Expected<double> one = time_reference();
  if (!one) return one.error();
  reference_frames_ = int(std::clamp(std::ceil(kReferenceSeconds / *one), 1.0, 1000.0));
  quickest_reference_ = kInfinity;  // the single frame above is not a reference time
  std::vector<double> times;
  for (int k = 0; k < 5; ++k) {
    Expected<double> t = time_reference();
    if (!t) return t.error();
    times.push_back(*t);
  }
  quickest_reference_ = median(times);
  return ok_status();
}

// The reference frames in a row: their time joins the point's slowest and the study's quickest.
Expected<double> Sweep::time_reference() {
  double total = 0;
  for (int k = 0; k < reference_frames_; ++k) {
    Expected<double> t = reference_->time_frame(0);
    if (!t) return t.error();
    total += *t;
  }
  slowest_reference_ = std::max(slowest_reference_, total);
  quickest_reference_ = std::min(quickest_reference_, total);
  return total;
}

// Whether the current family's planned point (n, width) is this shard's to measure (every
// point is, unsharded).
bool Sweep::in_this_shard(size_t n, int width) const {
  if (!request_.shard) return true;
  for (size_t i = 0; i < plan_.size(); ++i)
    if (plan_[i].n == n && plan_[i].width == width)
      return in_shard(plan_offset_ + i, *request_.shard);
  return false;
}

// Times `request.repetitions` rounds; in each, every renderer once, in a fresh random order.
// Stops after the fifth round once `deadline` has passed.
void Sweep::time_rounds(const Family& family, size_t n, FrameSource& frames, double deadline,
                        std::vector<Measurement>& points, Status& status) {
  std::vector<size_t> order(points.size());
  slowest_reference_ = 0;
  if (Expected<double> t = time_reference(); !t) status = t.error();
  for (int round = 0; status && round < request_.repetitions; ++round) {
    if (round >= 5 && elapsed() > deadline) break;
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng_.below(i)]);
    for (size_t k = 0; k < order.size(); ++k) {
      progress(fmt::format("{} {} round {}/{} {}", family.name, point_name(family, n), round + 1,
                           request_.repetitions, request_.renderers[order[k]]));
      if (cancelled()) return;
      Expected<double> t = frames.time_frame(order[k]);
      if (!t) {
        status = t.error();
        return;
      }
      points[order[k]].seconds.push_back(*t);
      points[order[k]].order.push_back(int(k));
      for (const auto& [phase, seconds] : frames.last_phases())
        points[order[k]].phases[phase].push_back(seconds);
    }
    if (Expected<double> t = time_reference(); !t) status = t.error();
  }
}

// Measures builtin:<family>:<n> at `width` with every renderer; the points join the result.
Status Sweep::measure(const Family& family, size_t n, int width, double deadline) {
  progress(fmt::format("{} {} {}×{}: preparing", family.name, point_name(family, n), width,
                       width * 3 / 4));
  Expected<std::unique_ptr<FrameSource>> frames = hooks_.prepare(family, n, width);
  if (!frames) return frames.error();
  std::vector<Measurement> points;
  for (const std::string& name : request_.renderers) {
    Measurement m;
    m.renderer = name;
    m.scene = family.name;
    m.scene_n = double(n);
    m.n = (*frames)->axis_value();
    m.pixels = (*frames)->pixels();
    m.width = width;
    m.height = width * 3 / 4;
    points.push_back(m);
  }
  Status status = ok_status();
  time_rounds(family, n, **frames, deadline, points, status);
  if (!status) return status;
  if (cancelled()) return ok_status();  // the point is incomplete: dropped
  const double ratio = slowest_reference_ / quickest_reference_;
  for (Measurement& m : points) {
    m.reference_ratio = ratio;
    m.busy = ratio > kBusyRatio;
    result_.points.push_back(std::move(m));
  }
  measured_.insert({family.name, n, width});
  return ok_status();
}

// The midpoints (in log N) of every bracket of measured points between which two renderers of
// different loop orders change places.
std::vector<size_t> Sweep::crossover_midpoints(const Family& family) const {
  std::map<size_t, std::map<std::string, double>> t;  // n -> renderer -> median
  for (const Measurement& m : result_.points)
    if (m.scene == family.name && m.width == request_.width)
      t[size_t(m.scene_n)][m.renderer] = typical_seconds(m);
  std::set<size_t> mids;
  for (size_t i = 0; i < request_.renderers.size(); ++i)
    for (size_t j = i + 1; j < request_.renderers.size(); ++j) {
      const std::string &a = request_.renderers[i], &b = request_.renderers[j];
      if (!compared_pair(a, b)) continue;
      for (auto it = t.begin(); it != t.end() && std::next(it) != t.end(); ++it) {
        auto next = std::next(it);
        bool before = it->second.at(a) < it->second.at(b);
        bool after = next->second.at(a) < next->second.at(b);
        if (before != after)
          if (size_t mid = log_midpoint(it->first, next->first)) mids.insert(mid);
      }
    }
  return {mids.begin(), mids.end()};
}

Expected<bool> Sweep::try_point(const Family& family, size_t n, int width, double limit,
                                double share_end) {
  if (measured_.count({family.name, n, width})) return false;
  // A narrower frame costs no more than the full-width one the prediction is made from.
  if (!cost_.empty() && elapsed() + cost_.predict(n) > limit) return false;
  double before = elapsed();
  if (Status s = measure(family, n, width, share_end); !s) return s.error();
  if (width == request_.width) cost_.add(n, elapsed() - before);
  return true;
}

// The log-spaced sweep of N at the full width, stopped where a point would end past `limit`.
Status Sweep::sweep_n(const Family& family, double limit, double share_end) {
  for (size_t n : log_spaced(family.low, family.high, family.points)) {
    if (cancelled()) return ok_status();
    if (!in_this_shard(n, request_.width)) continue;
    Expected<bool> done = try_point(family, n, request_.width, limit, share_end);
    if (!done) return done.error();
    if (!*done) {
      result_.notes.push_back(
          fmt::format("{}: the sweep stopped below {} (its points would have overrun the budget)",
                      family.name, point_name(family, n)));
      break;
    }
  }
  return ok_status();
}

// The pixel count swept at the smallest, the middle and the largest N measured, so that the
// per-pixel terms can be told from the constant ones.
Status Sweep::sweep_pixels(const Family& family, double limit, double share_end) {
  std::vector<size_t> measured;
  for (const auto& [name, n, width] : measured_)
    if (name == family.name && width == request_.width) measured.push_back(n);
  std::sort(measured.begin(), measured.end());
  // A shard takes the pixel sweep at the N planned: the other shards measure the rest of them.
  if (request_.shard) measured = log_spaced(family.low, family.high, family.points);
  for (size_t n : pixel_sweep_ns(measured))
    for (int width : pixel_sweep_widths(request_.width)) {
      if (cancelled()) return ok_status();
      if (!in_this_shard(n, width)) continue;
      Expected<bool> done = try_point(family, n, width, limit, share_end);
      if (!done) return done.error();
      if (!*done && !measured_.count({family.name, n, width})) {
        result_.notes.push_back(fmt::format(
            "{}: the pixel sweep stopped at {}, {} wide (it would have overrun the budget)",
            family.name, point_name(family, n), width));
        return ok_status();
      }
    }
  return ok_status();
}

// The points of the family measured while the machine was busy, measured again (the busy ones
// replaced) while the share lasts; those still busy are said in the notes.
Status Sweep::measure_busy_points_again(const Family& family, double share_end) {
  std::set<std::pair<size_t, int>> busy;
  for (const Measurement& m : result_.points)
    if (m.scene == family.name && m.busy) busy.insert({size_t(m.scene_n), m.width});
  size_t again = 0;
  for (auto [n, width] : busy) {
    if (cancelled() || elapsed() + cost_.predict(n) > share_end) break;
    auto same_point = [&, n = n, width = width](const Measurement& m) {
      return m.scene == family.name && size_t(m.scene_n) == n && m.width == width;
    };
    std::vector<Measurement> before;
    for (const Measurement& m : result_.points)
      if (same_point(m)) before.push_back(m);
    std::erase_if(result_.points, same_point);
    measured_.erase({family.name, n, width});
    if (Status s = measure(family, n, width, share_end); !s) return s;
    if (!measured_.count({family.name, n, width})) {  // cancelled: the first measurement stays
      for (Measurement& m : before) result_.points.push_back(std::move(m));
      break;
    }
    ++again;
  }
  if (again > 0)
    result_.notes.push_back(fmt::format(
        "{}: {} {} measured while the machine was busy with something else {} "
        "measured again",
        family.name, again, again == 1 ? "point" : "points", again == 1 ? "was" : "were"));
  size_t still = 0;
  double worst = 0;
  for (const Measurement& m : result_.points)
    if (m.scene == family.name && m.busy) ++still, worst = std::max(worst, m.reference_ratio);
  if (still > 0)
    result_.notes.push_back(fmt::format(
        "{}: {} measurements were taken while the machine was busy with something else (the "
        "reference frame up to {:.1f}× slower than its quickest) and are left out of the fits "
        "and crossovers: run the study on a quiet machine",
        family.name, still, worst));
  return ok_status();
}

// The sweep of N up to kBaseShare of the scene's share, of the pixel count up to kPixelShare,
// then points near crossovers, then busy points again.
Status Sweep::run_scene(const Family& family, double share_end) {
  const double share_start = elapsed();
  const double length = share_end - share_start;
  cost_ = CostPredictor();
  plan_offset_ += plan_.size();
  plan_ = planned_points(family, request_.width);
  if (Status s = start_reference(family); !s) return s;
  if (Status s = sweep_n(family, share_start + kBaseShare * length, share_end); !s) return s;
  if (Status s = sweep_pixels(family, share_start + kPixelShare * length, share_end); !s) return s;
  // A shard adds none near crossovers: where they go depends on the other shards' points.
  for (int round = 0; round < (request_.shard ? 0 : kRefinementRounds); ++round)
    for (size_t mid : crossover_midpoints(family)) {
      if (cancelled()) return ok_status();
      Expected<bool> done = try_point(family, mid, request_.width, share_end, share_end);
      if (!done) return done.error();
    }
  return measure_busy_points_again(family, share_end);
}

}  // namespace

Expected<StudyResult> run_study(const StudyRequest& request, const StudyHooks& hooks) {
  if (Status s = validate(request); !s) return s.error();
  StudyResult result;
  result.renderers = request.renderers;
  result.width = request.width;
  result.height = request.width * 3 / 4;
  result.mode = to_string(request.mode);
  result.budget_seconds = request.budget_seconds;
  result.repetitions = request.repetitions;
  result.seed = request.seed;
  result.bootstrap_replicates = request.bootstrap_replicates;
  result.shard = request.shard;
  if (request.shard)
    result.notes.push_back(fmt::format(
        "shard {}/{}: only the planned points whose index is {} mod {} were measured, none near "
        "crossovers, and no crossover is checked (they depend on the other shards' points); rvr "
        "study --merge pools the shards",
        request.shard->index, request.shard->count, request.shard->index, request.shard->count));
  Sweep sweep(request, hooks, result);
  std::vector<Family> families;
  for (size_t i = 0; i < request.scenes.size(); ++i) {
    Family family = *find_family(request.scenes[i]);
    families.push_back(family);
    result.scenes.push_back(family.name);
    result.axes[family.name] = family.axis;
    double left = request.budget_seconds - sweep.elapsed();
    double share_end = sweep.elapsed() + left / double(request.scenes.size() - i);
    if (Status s = sweep.run_scene(family, share_end); !s) return s.error();
    if (sweep.cancelled()) break;
  }
  if (sweep.cancelled()) {
    result.interrupted = true;
    result.notes.push_back(
        "the study was interrupted: it is concluded from the points measured "
        "before the interruption");
  }
  result.elapsed_seconds = sweep.elapsed();
  BootstrapOptions boot{request.bootstrap_replicates, request.seed};
  conclude(result, boot);
  if (!result.interrupted && request.check_predictions && !request.shard)
    if (Status s = check_predictions(request, hooks, families, result); !s) return s.error();
  return result;
}

}  // namespace rvr::study
