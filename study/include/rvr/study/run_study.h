// Running a study: for each scene family, within a share of the time budget, a log-spaced
// sweep of N at the full width and a sweep of the pixel count at three of those N, measured in
// one session (a fresh process) after another, then points added near every crossover; in each
// session the points in a fresh random order (the first session in increasing N, to learn what
// the budget holds), each point's renderers timed in rounds interleaved in random order; then
// the conclusions.
//
// Whether the machine stayed quiet is watched two ways. Relatively: a reference frame (the
// family's smallest point at full width, the first renderer, run enough times in a row to take
// 10 ms) is timed before the first round of every run and after each round; a run whose
// reference ran kBusyRatio slower than the family's quickest reference was measured while
// something else ran. Absolutely: each session begins with a probe of the machine
// (system_probe.h); a session that found other work on the CPUs marks its runs busy too. Busy
// runs are measured again in a fresh session as the budget allows; those left stay in the
// paired comparisons (their ratios carry their own wider spread) but not in the absolute times
// the models are fitted to, where a quiet run of the point exists.
#pragma once

#include <stddef.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/study/measurement.h"
#include "rvr/study/memory_estimate.h"
#include "rvr/study/study.h"
#include "rvr/study/sweep_plan.h"
#include "rvr/study/system_probe.h"

namespace rvr::study {

struct StudyRequest {
  std::vector<std::string> scenes;     // "builtin:tessphere", ...
  std::vector<std::string> renderers;  // names or variants in the renderer table
  int width = 1024;                    // height = width * 3/4
  RenderMode mode = RenderMode::Local;
  double budget_seconds = 300;
  int repetitions = 5;  // rounds per run
  int sessions = 3;     // runs per point, each in a fresh session
  // The smallest difference the study calls one renderer faster than another: a ratio of
  // 1 + noise_threshold (as Criterion.rs's noise threshold).
  double noise_threshold = 0.03;
  uint64_t seed = 1;
  int bootstrap_replicates = 1000;
  // After the conclusions, each crossover along N is measured again at a third of and three
  // times its value (prediction_checks.h); outside the budget. Not in a shard.
  bool check_predictions = true;
  // Measure only this shard's planned points, and add none near crossovers (they depend on the
  // other shards' points): for studies merged afterwards (merge.h).
  std::optional<Shard> shard;
};

// One frame timed.
struct FrameTime {
  double seconds = 0;
  std::map<std::string, double> phases;  // "zbuffer", "trace" for the hybrids, in seconds
};

// One scene size with every renderer of the study ready to render it (what they build per
// scene already built, a first frame already rendered).
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual double axis_value() const = 0;  // triangles drawn (or occluders' N)
  virtual double pixels() const = 0;
  // The wall time of preparing renderer `index` (in the request's order) for this scene: what
  // it builds per scene (the tracers' BVH), paid again whenever the scene changes.
  virtual double prepare_seconds(size_t index) const = 0;
  // Renderer `index`'s own count of the work of one frame (measurement.h).
  virtual std::map<std::string, double> counters(size_t index) const = 0;
  // In full mode with raytrace among the renderers: renderer `index`'s error in each effect's
  // mask against raytrace's frame of this scene (Measurement::effect_errors). Empty else.
  virtual std::vector<PointEffectError> effect_errors(size_t /*index*/) const { return {}; }
  // One frame of renderer `index`.
  virtual Expected<FrameTime> time_frame(size_t index) = 0;
};

// A session of the study: in the CLI a fresh process, in which scenes are prepared one after
// another; in-process, scenes prepared afresh. Its FrameSources live no longer than it.
class Session {
 public:
  virtual ~Session() = default;
  virtual std::string kind() const = 0;  // "process" or "preparation"
  // The FrameSource of builtin:<family>:<n> (or n copies of the family's file) at
  // `width` × width·3/4 pixels.
  virtual Expected<std::unique_ptr<FrameSource>> prepare(const Family& family, size_t n,
                                                         int width) = 0;
  // The budget's clock, read while the session prepares or times a frame: once `seconds_left`
  // returns <= 0 the step is stopped and fails with ErrorKind::OutOfTime (a process session
  // kills its worker; the session is of no use after). A session that cannot stop a step
  // ignores it: the step ends when it ends.
  virtual void stop_steps_when_out_of_time(const std::function<double()>& /*seconds_left*/) {}
};

using StartSession = std::function<Expected<std::unique_ptr<Session>>()>;

struct StudyHooks {
  StartSession start_session;
  std::function<double()> now;  // seconds on a steady clock; null: std::chrono::steady_clock
  std::function<void(const std::string& what)> on_progress;  // null: nothing shown
  // Polled between frames; true stops the sweep (the point being measured is dropped) and the
  // study is concluded from the points measured so far, with `interrupted` set.
  std::function<bool()> cancelled;
  // The machine's state, waiting `window` seconds; null: probe_system. Tests replace it.
  std::function<SystemSnapshot(double window)> probe;
  // A session's memory at one point, measured in a fresh process (memory_estimate.h): before a
  // family's sweep starts its first point above the probes' N, the family is probed and its
  // planned N that would not fit in the memory available are dropped, with a note. Null: no
  // estimate, nothing dropped.
  ProbeMemory probe_memory;
  // The memory available (bytes) the estimate is checked against; null: MemAvailable.
  std::function<double()> available_memory;
};

// Validates the request (families, renderer names, budget, width, repetitions, sessions:
// BadInput errors before any work), sweeps (each family's large N checked against the memory
// first: hooks.probe_memory), fits and concludes. The machine facts are left for the caller.
Expected<StudyResult> run_study(const StudyRequest& request, const StudyHooks& hooks);

}  // namespace rvr::study
