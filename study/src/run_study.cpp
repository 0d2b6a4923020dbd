// The study's sweep within its budget (see run_study.h).
#include "rvr/study/run_study.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <type_traits>
#include <utility>
#include <variant>

#include "rvr/core/check.h"
#include "rvr/renderers/registry.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/crossover.h"
#include "rvr/study/measurement.h"
#include "rvr/study/prediction_checks.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study {
namespace {

// Of the budget share of a scene, where the log-spaced sweep of N must end (all its sessions
// counted), and the sweep of the pixel count; the rest is for the points added near crossovers
// and for busy runs measured again.
constexpr double kBaseShare = 0.6;
constexpr double kPixelShare = 0.8;
constexpr int kRefinementRounds = 3;
// Of the whole budget, what the prediction checks keep (when they run).
constexpr double kCheckShare = 0.15;
// How long one timing of the reference frame takes at least, in frames in a row: a whole frame
// at full width touches the frame buffers, so memory contention shows as well as CPU time.
constexpr double kReferenceSeconds = 10e-3;
// How long the system probe waits (idle) to see what else uses the CPUs.
constexpr double kProbeWindow = 0.2;
// A step still running this long before the budget's end is stopped, so that stopping it (a
// worker killed, its run dropped) ends within the budget.
constexpr double kStoppingSeconds = 0.01;
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
  if (r.repetitions < 3)
    return bad_input(fmt::format("--repetitions: must be >= 3, got {}", r.repetitions));
  // Fewer, and the spread between processes cannot be told from that between frames.
  if (r.sessions < 3)
    return bad_input(fmt::format("--processes: must be >= 3, got {}", r.sessions));
  if (!(r.noise_threshold >= 0 && r.noise_threshold < 1))
    return bad_input(fmt::format("--noise-threshold: must be in 0 .. 1 (a ratio minus 1), got {}",
                                 r.noise_threshold));
  if (r.shard && (r.shard->count < 1 || r.shard->index >= r.shard->count))
    return bad_input(fmt::format("--shard: must be I/N with 0 <= I < N, got {}/{}", r.shard->index,
                                 r.shard->count));
  return ok_status();
}

// A point of a family in words: "N=1000", or "12 copies" of a file.
std::string point_name(const Family& family, size_t n) {
  return family.source.empty() ? fmt::format("N={}", n) : fmt::format("{} copies", n);
}

// A unique name for one sweep: 16 hex digits from the OS's random source and the clock.
std::string new_run_id() {
  std::random_device device;
  uint64_t bits = (uint64_t(device()) << 32) ^ uint64_t(device());
  bits ^= uint64_t(std::chrono::system_clock::now().time_since_epoch().count());
  return fmt::format("{:016x}", bits);
}

using PointKey = std::pair<size_t, int>;  // scene N, width

// Where measured points go: the sweep's, or the prediction checks'. For each (n, width), the
// index in `list` of the first renderer's measurement (the others follow in the request's
// order).
struct PointSet {
  std::vector<Measurement>* list = nullptr;
  std::map<PointKey, size_t> index;
};

// What the sweep keeps per family.
struct FamilyState {
  PointSet points, checks;
  std::vector<PointKey> first_session_order;  // as measured in the family's first session
  CostPredictor cost;                         // one run's wall time at full width, by N
  int reference_frames = 1;                   // frames in a row per reference time
  double quickest_reference = kInfinity;      // its quickest time in the family so far
  std::vector<PlannedPoint> plan;
  size_t plan_offset = 0;  // the index of its first point in the study's plan
  // The largest N a session may hold (memory_estimate.h; 0: no limit), once checked.
  size_t max_n = 0;
  bool memory_checked = false;
};

// A session opened for one family: the session, its reference frame and what its probe saw.
struct OpenSession {
  std::unique_ptr<Session> session;
  std::unique_ptr<FrameSource> reference;
  int index = 0;            // into StudyResult::sessions
  bool other_work = false;  // its system probe saw other work on the CPUs
};

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
    if (!hooks_.probe) hooks_.probe = probe_system;
    start_ = hooks_.now();
  }

  // Seconds of measuring: the time since the start but for what exclude() took out.
  double elapsed() const { return hooks_.now() - start_ - excluded_; }
  // Takes `seconds` (the fits between the sweep and the checks) out of the budget's clock.
  void exclude(double seconds) { excluded_ += seconds; }
  bool cancelled() const { return hooks_.cancelled && hooks_.cancelled(); }
  // The budget is a limit: no frame, preparation or session is started that would end past it,
  // were it as long as the longest such step so far; a step still running at its end is
  // stopped by its session (Session::stop_steps_when_out_of_time) and its run dropped.
  bool out_of_time() const { return elapsed() + longest_step_ > request_.budget_seconds; }
  // f(), a frame, a preparation or a session's opening, its duration kept as the longest step
  // when it is.
  template <class F>
  auto timed_step(F&& f) {
    const double before = elapsed();
    auto result = f();
    longest_step_ = std::max(longest_step_, elapsed() - before);
    return result;
  }
  bool stopped() const { return cancelled() || out_of_time(); }
  // A step stopped at the budget's end ends the measuring as running out of time between steps
  // does: the run it belonged to was never added. Other errors pass.
  Status unless_out_of_time(Status s) {
    if (s || s.error().kind != ErrorKind::OutOfTime) return s;
    step_stopped_ = true;
    return ok_status();
  }
  // Whether a step was stopped at the budget's end.
  bool step_stopped() const { return step_stopped_; }
  SystemSnapshot probe() const {
    SystemSnapshot s = hooks_.probe(kProbeWindow);
    s.at = elapsed();
    return s;
  }

  Status run_family(const Family& family, double share_end);
  // The prediction checks' points (prediction_checks.h), each in S fresh sessions, while the
  // budget lasts; into result.check_points.
  Status measure_checks(const std::vector<Family>& families);

 private:
  Expected<OpenSession> open_session(const Family& family) {
    return timed_step([&] { return open_new_session(family); });
  }
  Expected<OpenSession> open_new_session(const Family& family);
  Expected<double> time_reference(FrameSource& reference);
  Status measure_run(const Family& family, size_t n, int width, OpenSession& session,
                     PointSet& into);
  void time_rounds(const std::string& what, FrameSource& frames, FrameSource& reference,
                   std::vector<Run>& runs, Status& status);
  Expected<bool> try_first_run(const Family& family, size_t n, int width, double limit,
                               OpenSession& session);
  Status sweep_n(const Family& family, double limit, OpenSession& session);
  Status check_memory(const Family& family);
  Status sweep_pixels(const Family& family, double limit, OpenSession& session);
  Status more_sessions(const Family& family, double limit);
  Status refine_near_crossovers(const Family& family, double share_end);
  Status measure_busy_runs_again(const Family& family, double share_end);
  std::vector<size_t> crossover_midpoints(const Family& family) const;
  bool in_this_shard(size_t n, int width) const;
  void progress(const std::string& what) const {
    if (hooks_.on_progress) hooks_.on_progress(what);
  }

  const StudyRequest& request_;
  StudyHooks hooks_;
  StudyResult& result_;
  Rng rng_;
  double start_ = 0, excluded_ = 0;
  double longest_step_ = 0;  // seconds of the longest step so far (timed_step)
  bool step_stopped_ = false;
  std::map<std::string, FamilyState> families_;
  FamilyState* f_ = nullptr;  // the family being measured
  size_t plan_size_ = 0;      // of the families swept so far
};

// A fresh session: the machine probed, the family's reference frame (its smallest point at
// full width, the first renderer) prepared in it and timed five times. In the family's first
// session the reference's frames in a row are chosen to take kReferenceSeconds (a frame of a
// few microseconds alone would measure the timer and the scheduler).
Expected<OpenSession> Sweep::open_new_session(const Family& family) {
  OpenSession open;
  SessionInfo info;
  info.system = probe();
  info.study = result_.run_id;
  open.other_work = shows_other_work(info.system);
  RVR_TRY_ASSIGN(session, hooks_.start_session());
  open.session = std::move(*session);
  open.session->stop_steps_when_out_of_time(
      [this] { return request_.budget_seconds - kStoppingSeconds - elapsed(); });
  info.kind = open.session->kind();
  open.index = int(result_.sessions.size());
  result_.sessions.push_back(info);
  RVR_TRY_ASSIGN(reference, open.session->prepare(family, family.low, request_.width));
  open.reference = std::move(*reference);
  if (f_->quickest_reference == kInfinity) {
    f_->reference_frames = 1;
    RVR_TRY_ASSIGN(one, open.reference->time_frame(0));
    f_->reference_frames =
        int(std::clamp(std::ceil(kReferenceSeconds / one->seconds), 1.0, 1000.0));
  }
  std::vector<double> times;
  for (int k = 0; k < 5 && !stopped(); ++k) {
    RVR_TRY_ASSIGN(t, time_reference(*open.reference));
    times.push_back(*t);
  }
  if (!times.empty()) f_->quickest_reference = std::min(f_->quickest_reference, median(times));
  return open;
}

// The reference frames in a row, timed together.
Expected<double> Sweep::time_reference(FrameSource& reference) {
  double total = 0;
  for (int k = 0; k < f_->reference_frames; ++k) {
    RVR_TRY_ASSIGN(t, reference.time_frame(0));
    total += t->seconds;
  }
  return total;
}

// Whether the current family's planned point (n, width) is this shard's to measure (every
// point is, unsharded).
bool Sweep::in_this_shard(size_t n, int width) const {
  if (!request_.shard) return true;
  for (size_t i = 0; i < f_->plan.size(); ++i)
    if (f_->plan[i].n == n && f_->plan[i].width == width)
      return in_shard(f_->plan_offset + i, *request_.shard);
  return false;
}

// `request.repetitions` rounds, in each every renderer once in a fresh random order, with the
// reference timed before the first and after each; a run's reference_ratio is its slowest
// reference over the family's quickest. Stops (status ok, runs incomplete) when the study is
// cancelled or out of time.
void Sweep::time_rounds(const std::string& what, FrameSource& frames, FrameSource& reference,
                        std::vector<Run>& runs, Status& status) {
  std::vector<size_t> order(runs.size());
  double slowest = 0;
  auto reference_time = [&] {
    Expected<double> t = time_reference(reference);
    if (!t) return status = t.error(), false;
    slowest = std::max(slowest, *t);
    f_->quickest_reference = std::min(f_->quickest_reference, *t);
    return true;
  };
  if (!reference_time()) return;
  for (int round = 0; round < request_.repetitions; ++round) {
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng_.below(i)]);
    for (size_t k = 0; k < order.size(); ++k) {
      progress(fmt::format("{} round {}/{} {}", what, round + 1, request_.repetitions,
                           request_.renderers[order[k]]));
      if (stopped()) return;
      Expected<FrameTime> t = timed_step([&] { return frames.time_frame(order[k]); });
      if (!t) {
        status = t.error();
        return;
      }
      Run& run = runs[order[k]];
      run.seconds.push_back(t->seconds);
      run.order.push_back(int(k));
      for (const auto& [phase, seconds] : t->phases) run.phases[phase].push_back(seconds);
    }
    if (!reference_time()) return;
  }
  for (Run& run : runs) run.reference_ratio = slowest / f_->quickest_reference;
}

// One run of builtin:<family>:<n> at `width` in `session`, every renderer: added to the
// family's points (created at the point's first run). A run cut short is dropped.
Status Sweep::measure_run(const Family& family, size_t n, int width, OpenSession& session,
                          PointSet& into) {
  const std::string what = fmt::format("{} {} {}×{} session {}", family.name, point_name(family, n),
                                       width, width * 3 / 4, session.index + 1);
  if (stopped()) return ok_status();
  progress(what + ": preparing");
  RVR_TRY_ASSIGN(frames, timed_step([&] { return session.session->prepare(family, n, width); }));
  std::vector<Run> runs(request_.renderers.size());
  for (size_t i = 0; i < runs.size(); ++i) {
    runs[i].session = session.index;
    runs[i].prepare_seconds = (*frames)->prepare_seconds(i);
  }
  Status status = ok_status();
  time_rounds(what, **frames, *session.reference, runs, status);
  if (!status) return status;
  if (runs[0].seconds.size() < size_t(request_.repetitions)) return ok_status();  // cut short
  std::vector<Measurement>& list = *into.list;
  auto [it, fresh] = into.index.try_emplace({n, width}, list.size());
  if (!fresh) {
    // A point seen before: none of its runs is this session's (a fresh one is not in the list
    // yet).
    for (const Run& held : list[it->second].runs)
      RVR_DCHECK(held.session != session.index, "one run per session and point: session ",
                 session.index, " measured ", family.name, ":", n, " twice");
  }
  for (size_t i = 0; i < runs.size(); ++i) {
    runs[i].busy = runs[i].reference_ratio > kBusyRatio || session.other_work;
    if (fresh) {
      Measurement m;
      m.renderer = request_.renderers[i];
      m.scene = family.name;
      m.scene_n = double(n);
      m.n = (*frames)->axis_value();
      m.pixels = (*frames)->pixels();
      m.width = width;
      m.height = width * 3 / 4;
      m.counters = (*frames)->counters(i);
      m.effect_errors = (*frames)->effect_errors(i);
      list.push_back(std::move(m));
    }
    list[it->second + i].runs.push_back(std::move(runs[i]));
  }
  return ok_status();
}

// The midpoints (in log N) of every bracket of neighbouring points between which the trend of
// two renderers' ratio (crossover.h) changes sign: where a crossover lies, judged on the trend,
// not on single points that noise can swap.
std::vector<size_t> Sweep::crossover_midpoints(const Family& family) const {
  std::map<std::string, std::vector<Measurement>> along_n;
  for (const Measurement& m : result_.points)
    if (m.scene == family.name && m.width == request_.width) along_n[m.renderer].push_back(m);
  const CompareOptions options{BootstrapOptions{200, request_.seed}, request_.noise_threshold};
  std::set<size_t> mids;
  for (size_t i = 0; i < request_.renderers.size(); ++i)
    for (size_t j = i + 1; j < request_.renderers.size(); ++j) {
      const std::string &a = request_.renderers[i], &b = request_.renderers[j];
      if (!compared_pair(a, b)) continue;
      const Comparison c = compare_curves(along_n[a], along_n[b], family.axis, options).comparison;
      if (!c.inconclusive.empty()) continue;
      for (size_t k = 0; k + 1 < c.points.size(); ++k) {
        if ((c.points[k].trend < 1) == (c.points[k + 1].trend < 1)) continue;
        // The scene N of the two points (the axis value is the triangles drawn).
        size_t low = 0, high = 0;
        for (const Measurement& m : along_n[a]) {
          if (m.n == c.points[k].at) low = size_t(m.scene_n);
          if (m.n == c.points[k + 1].at) high = size_t(m.scene_n);
        }
        if (size_t mid = log_midpoint(low, high)) mids.insert(mid);
      }
    }
  return {mids.begin(), mids.end()};
}

// A point's first run, in the family's first session, unless it was measured, or all of its
// sessions would end past `limit` as predicted from the points measured at the full width, or
// it would not fit in the memory (checked before the first point larger than the memory
// probes'): false then.
Expected<bool> Sweep::try_first_run(const Family& family, size_t n, int width, double limit,
                                    OpenSession& session) {
  if (f_->points.index.count({n, width})) return false;
  // The sessions still to come repeat every point measured so far, and this one.
  double committed = 0;
  for (PointKey p : f_->first_session_order) committed += f_->cost.predict(p.first);
  const double sessions_left = double(request_.sessions - 1);
  // A narrower frame costs no more than the full-width one the prediction is made from.
  if (!f_->cost.empty() &&
      elapsed() + f_->cost.predict(n) * double(request_.sessions) + sessions_left * committed >
          limit)
    return false;
  // Up to the largest probe's N a session holds no more than the probe did.
  if (!f_->memory_checked && hooks_.probe_memory && n > memory_probe_ns(family).back())
    RVR_TRY(check_memory(family));
  if (f_->max_n > 0 && n > f_->max_n) return false;
  double before = elapsed();
  RVR_TRY(measure_run(family, n, width, session, f_->points));
  if (!f_->points.index.count({n, width})) return false;  // cut short
  if (width == request_.width) f_->cost.add(n, elapsed() - before);
  f_->first_session_order.push_back({n, width});
  return true;
}

// The log-spaced sweep of N at the full width, stopped where a point would end past `limit`.
Status Sweep::sweep_n(const Family& family, double limit, OpenSession& session) {
  for (size_t n : sweep_ns(family)) {
    if (stopped()) return ok_status();
    if (!in_this_shard(n, request_.width)) continue;
    RVR_TRY_ASSIGN(done, try_first_run(family, n, request_.width, limit, session));
    if (!*done) {
      if (f_->max_n == 0 || n <= f_->max_n)  // else the memory's note says why
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
Status Sweep::sweep_pixels(const Family& family, double limit, OpenSession& session) {
  std::vector<size_t> measured;
  for (const auto& [point, index] : f_->points.index)
    if (point.second == request_.width) measured.push_back(point.first);
  std::sort(measured.begin(), measured.end());
  // A shard takes the pixel sweep at the N planned: the other shards measure the rest of them.
  if (request_.shard) measured = sweep_ns(family);
  for (size_t n : pixel_sweep_ns(measured))
    for (int width : pixel_sweep_widths(request_.width)) {
      if (stopped()) return ok_status();
      if (!in_this_shard(n, width)) continue;
      RVR_TRY_ASSIGN(done, try_first_run(family, n, width, limit, session));
      if (!*done && !f_->points.index.count({n, width})) {
        result_.notes.push_back(fmt::format(
            "{}: the pixel sweep stopped at {}, {} wide (it would have overrun the budget)",
            family.name, point_name(family, n), width));
        return ok_status();
      }
    }
  return ok_status();
}

// Sessions 2 … S: every point of the first session measured again, in a fresh random order.
Status Sweep::more_sessions(const Family& family, double limit) {
  size_t skipped = 0;
  for (int s = 1; s < request_.sessions; ++s) {
    if (stopped()) return ok_status();
    RVR_TRY_ASSIGN(session, open_session(family));
    std::vector<PointKey> order = f_->first_session_order;
    for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng_.below(i)]);
    for (PointKey p : order) {
      if (stopped()) return ok_status();
      if (elapsed() + f_->cost.predict(p.first) > limit) {
        ++skipped;
        continue;
      }
      RVR_TRY(measure_run(family, p.first, p.second, *session, f_->points));
    }
  }
  if (skipped > 0)
    result_.notes.push_back(fmt::format(
        "{}: {} runs of points already measured were left out (they would have overrun the "
        "budget): those points were measured in fewer than {} sessions",
        family.name, skipped, request_.sessions));
  return ok_status();
}

// Up to kRefinementRounds rounds: points at the midpoints of brackets where two renderers change
// places, each measured in S fresh sessions, as the share allows.
Status Sweep::refine_near_crossovers(const Family& family, double share_end) {
  for (int round = 0; round < kRefinementRounds; ++round) {
    std::vector<size_t> mids;
    double cost = 0;
    for (size_t mid : crossover_midpoints(family))
      if (!f_->points.index.count({mid, request_.width})) {
        const double one = double(request_.sessions) * f_->cost.predict(mid);
        if (elapsed() + cost + one > share_end) continue;
        mids.push_back(mid);
        cost += one;
      }
    if (mids.empty()) return ok_status();
    for (int s = 0; s < request_.sessions; ++s) {
      if (stopped()) return ok_status();
      RVR_TRY_ASSIGN(session, open_session(family));
      for (size_t i = mids.size(); i > 1; --i) std::swap(mids[i - 1], mids[rng_.below(i)]);
      for (size_t mid : mids) {
        if (stopped()) return ok_status();
        RVR_TRY(measure_run(family, mid, request_.width, *session, f_->points));
      }
    }
  }
  return ok_status();
}

// The family's runs measured while the machine was busy, measured again in a fresh session
// while the share lasts: a quiet run replaces the busy one. Notes say how many and what is left.
Status Sweep::measure_busy_runs_again(const Family& family, double share_end) {
  // Each round a fresh session measures every point that still has a busy run once; a quiet
  // run replaces one busy run. Rounds go on while they replace something and the share lasts.
  size_t replaced = 0;
  for (size_t in_round = 1; in_round > 0;) {
    in_round = 0;
    std::vector<PointKey> busy;
    for (const auto& [point, index] : f_->points.index)
      for (const Run& run : result_.points[index].runs)
        if (run.busy) {
          busy.push_back(point);
          break;
        }
    if (busy.empty() || stopped() || elapsed() + f_->cost.predict(busy[0].first) > share_end) break;
    RVR_TRY_ASSIGN(session, open_session(family));
    for (PointKey point : busy) {
      if (stopped() || elapsed() + f_->cost.predict(point.first) > share_end) break;
      const size_t first = f_->points.index.at(point);
      const size_t before = result_.points[first].runs.size();
      RVR_TRY(measure_run(family, point.first, point.second, *session, f_->points));
      if (result_.points[first].runs.size() == before) break;  // cut short
      if (result_.points[first].runs.back().busy) continue;    // busy again: both kept
      // The first busy run goes, for every renderer (their runs of a session go together).
      int busy_session = -1;
      for (const Run& run : result_.points[first].runs)
        if (run.busy) {
          busy_session = run.session;
          break;
        }
      for (size_t i = 0; i < request_.renderers.size(); ++i)
        std::erase_if(result_.points[first + i].runs,
                      [&](const Run& r) { return r.session == busy_session; });
      ++in_round;
    }
    replaced += in_round;
  }
  if (replaced > 0)
    result_.notes.push_back(fmt::format(
        "{}: {} {} measured while the machine was busy with something else {} measured again",
        family.name, replaced, replaced == 1 ? "run" : "runs", replaced == 1 ? "was" : "were"));
  size_t still = 0, points = 0;
  double worst = 0;
  for (const auto& [point, index] : f_->points.index) {
    bool any = false;
    for (const Run& run : result_.points[index].runs)
      if (run.busy) ++still, any = true, worst = std::max(worst, run.reference_ratio);
    points += any;
  }
  if (still > 0)
    result_.notes.push_back(fmt::format(
        "{}: {} runs at {} points were measured while the machine was busy with something else "
        "(the reference frame up to {:.1f}× slower than its quickest, or other work seen by the "
        "system probe): their paired ratios count, with the spread they have; their absolute "
        "times are fitted only where no quiet run of the point exists",
        family.name, still, points, worst));
  return ok_status();
}

// Before the sweep starts a point larger than the memory probes' (memory_estimate.h): the
// family's memory estimated, the planned N that would not fit dropped (f_->max_n) with a note.
// The probes run in fresh processes beside the open session; their time is not the budget's.
Status Sweep::check_memory(const Family& family) {
  f_->memory_checked = true;
  const double before = elapsed();
  progress(family.name + ": estimating memory");
  const double available =
      hooks_.available_memory ? hooks_.available_memory() : available_memory_bytes();
  Expected<FamilyMemory> m = check_family_memory(family, request_.renderers, request_.width,
                                                 hooks_.probe_memory, available);
  exclude(elapsed() - before);
  if (!m) return m.error();
  if (!m->dropped.empty()) {
    f_->max_n = std::max<size_t>(m->max_n, 1);
    result_.notes.push_back(memory_note(*m));
  }
  result_.memory.push_back(std::move(*m));
  return ok_status();
}

// The first session sweeps N up to kBaseShare of the scene's share and the pixel count up to
// kPixelShare (every session to come counted); sessions 2 … S repeat those points; then points
// near crossovers, then busy runs again.
Status Sweep::run_family(const Family& family, double share_end) {
  const double share_start = elapsed();
  const double length = share_end - share_start;
  f_ = &families_[family.name];
  f_->points.list = &result_.points;
  f_->checks.list = &result_.check_points;
  f_->plan = planned_points(family, request_.width);
  f_->plan_offset = plan_size_;
  plan_size_ += f_->plan.size();
  {
    RVR_TRY_ASSIGN(first, open_session(family));
    RVR_TRY(sweep_n(family, share_start + kBaseShare * length, *first));
    RVR_TRY(sweep_pixels(family, share_start + kPixelShare * length, *first));
  }
  RVR_TRY(more_sessions(family, share_start + kPixelShare * length));
  // A shard adds none near crossovers: where they go depends on the other shards' points.
  if (!request_.shard) RVR_TRY(refine_near_crossovers(family, share_end));
  return measure_busy_runs_again(family, share_end);
}

Status Sweep::measure_checks(const std::vector<Family>& families) {
  const std::vector<CheckPoint> plan = plan_checks(result_);
  size_t skipped = 0, too_large = 0;
  for (int s = 0; s < request_.sessions; ++s)
    for (const Family& family : families) {
      std::vector<PointKey> points;
      for (const CheckPoint& p : plan)
        if (p.scene == family.name &&
            std::find(points.begin(), points.end(), PointKey{p.scene_n, p.width}) == points.end())
          points.push_back({p.scene_n, p.width});
      if (points.empty() || stopped()) continue;
      f_ = &families_[family.name];
      RVR_TRY_ASSIGN(session, open_session(family));
      for (size_t i = points.size(); i > 1; --i) std::swap(points[i - 1], points[rng_.below(i)]);
      for (PointKey p : points) {
        if (stopped()) break;
        // A point the memory check found too large for a session is not measured.
        if (f_->max_n > 0 && p.first > f_->max_n) {
          ++too_large;
          continue;
        }
        // Every session of the checks is to come: the point's share of what is left.
        if (elapsed() + f_->cost.predict(p.first) * double(request_.sessions - s) >
            request_.budget_seconds) {
          ++skipped;
          continue;
        }
        RVR_TRY(measure_run(family, p.first, p.second, *session, f_->checks));
      }
    }
  if (skipped > 0)
    result_.notes.push_back(fmt::format(
        "{} runs of the prediction checks were left out: they would have overrun the budget",
        skipped));
  if (too_large > 0)
    result_.notes.push_back(fmt::format(
        "{} runs of the prediction checks were left out: their points would not fit in the "
        "memory a session may take",
        too_large));
  return ok_status();
}

}  // namespace

Expected<StudyResult> run_study(const StudyRequest& request, const StudyHooks& hooks) {
  RVR_TRY(validate(request));
  StudyResult result;
  result.renderers = request.renderers;
  result.width = request.width;
  result.height = request.width * 3 / 4;
  result.mode = to_string(request.mode);
  result.budget_seconds = request.budget_seconds;
  result.repetitions = request.repetitions;
  result.sessions_per_point = request.sessions;
  result.noise_threshold = request.noise_threshold;
  result.seed = request.seed;
  result.bootstrap_replicates = request.bootstrap_replicates;
  result.shard = request.shard;
  result.run_id = new_run_id();
  if (request.shard)
    result.notes.push_back(fmt::format(
        "shard {}/{}: only the planned points whose index is {} mod {} were measured, none near "
        "crossovers, and no crossover is checked (they depend on the other shards' points); rvr "
        "study --merge pools the shards",
        request.shard->index, request.shard->count, request.shard->index, request.shard->count));
  Sweep sweep(request, hooks, result);
  result.system_before = sweep.probe();
  const bool checks = request.check_predictions && !request.shard;
  const double sweep_budget = request.budget_seconds * (checks ? 1 - kCheckShare : 1.0);
  std::vector<Family> families;
  for (size_t i = 0; i < request.scenes.size(); ++i) {
    Family family = *find_family(request.scenes[i]);
    families.push_back(family);
    result.scenes.push_back(family.name);
    result.axes[family.name] = family.axis;
    double left = sweep_budget - sweep.elapsed();
    double share_end = sweep.elapsed() + left / double(request.scenes.size() - i);
    if (sweep.stopped()) continue;
    RVR_TRY(sweep.unless_out_of_time(sweep.run_family(family, share_end)));
  }
  if (sweep.cancelled()) {
    result.interrupted = true;
    result.notes.push_back(
        "the study was interrupted: it is concluded from the points measured "
        "before the interruption");
  } else if (sweep.out_of_time()) {
    result.notes.push_back(fmt::format(
        "the budget of {:.0f} s ran out during the sweep: the run being measured was dropped",
        request.budget_seconds));
  }
  BootstrapOptions boot{request.bootstrap_replicates, request.seed};
  const double before_fits = sweep.elapsed();
  conclude(result, boot);
  sweep.exclude(sweep.elapsed() - before_fits);
  double measured = sweep.elapsed();
  if (!result.interrupted && checks && !sweep.stopped() && !result.crossovers.empty()) {
    RVR_TRY(sweep.unless_out_of_time(sweep.measure_checks(families)));
    if (sweep.step_stopped())
      result.notes.push_back(fmt::format(
          "the budget of {:.0f} s ran out during the prediction checks: the run being measured "
          "was stopped and dropped",
          request.budget_seconds));
    // Checks cut short are evaluated from the points they measured; not in the budget.
    measured = sweep.elapsed();
    evaluate_checks(result, CompareOptions{boot, request.noise_threshold});
    if (sweep.cancelled()) {
      result.interrupted = true;
      result.notes.push_back(
          "the study was interrupted during its prediction checks: only the checks measured "
          "before the interruption are given");
    }
  }
  result.elapsed_seconds = measured;
  result.system_after = sweep.probe();
  return result;
}

}  // namespace rvr::study
