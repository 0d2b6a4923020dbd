// Running a study: for each scene family, within a share of the time budget, a log-spaced
// sweep of N at the full width, a sweep of the pixel count at three of those N, and points added
// near every crossover; each point's frames timed with the renderers' repetitions interleaved in
// random order; then the conclusions.
//
// Whether the machine stayed quiet is watched: a reference frame (the family's smallest point,
// the first renderer, run enough times in a row to take 2 ms) is timed before the first round of
// every point and after each round. A point whose reference ran kBusyRatio slower than the
// quickest reference of the family was
// measured while something else ran: it is measured again at the end of the family's share if
// the budget allows, and a point still busy is kept (busy: true) but left out of the fits and
// crossovers.
#pragma once

#include <stddef.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rvr/shared/expected.h"
#include "rvr/shared/renderer.h"
#include "rvr/study/study.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study {

struct StudyRequest {
  std::vector<std::string> scenes;     // "builtin:tessphere", ...
  std::vector<std::string> renderers;  // names or variants in the renderer table
  int width = 1024;                    // height = width * 3/4
  RenderMode mode = RenderMode::Local;
  double budget_seconds = 300;
  int repetitions = 5;
  uint64_t seed = 1;
  int bootstrap_replicates = 1000;
  // After the conclusions, each crossover along N is measured again at a third of and three
  // times its value (prediction_checks.h); outside the budget. Not in a shard.
  bool check_predictions = true;
  // Measure only this shard's planned points, and add none near crossovers (they depend on the
  // other shards' points): for studies merged afterwards (merge.h).
  std::optional<Shard> shard;
};

// One scene size with every renderer of the study ready to render it (what they build per
// scene already built, a first frame already rendered).
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual double axis_value() const = 0;  // triangles drawn (or occluders' N)
  virtual double pixels() const = 0;
  // The wall time of one frame of renderer `index` (in the request's order).
  virtual Expected<double> time_frame(size_t index) = 0;
  // The phases of the last frame timed, in seconds ("zbuffer", "trace" for the hybrids).
  virtual std::map<std::string, double> last_phases() const { return {}; }
};

// Makes the FrameSource of builtin:<family>:<n> (or n copies of the family's file) at
// `width` × width·3/4 pixels.
using PrepareFrames = std::function<Expected<std::unique_ptr<FrameSource>>(const Family& family,
                                                                           size_t n, int width)>;

struct StudyHooks {
  PrepareFrames prepare;
  std::function<double()> now;  // seconds on a steady clock; null: std::chrono::steady_clock
  std::function<void(const std::string& what)> on_progress;  // null: nothing shown
  // Polled between frames; true stops the sweep (the point being measured is dropped) and the
  // study is concluded from the points measured so far, with `interrupted` set.
  std::function<bool()> cancelled;
};

// Validates the request (families, renderer names, budget, width, repetitions: BadInput errors
// before any work), sweeps, fits and concludes. The machine facts are left for the caller.
Expected<StudyResult> run_study(const StudyRequest& request, const StudyHooks& hooks);

}  // namespace rvr::study
