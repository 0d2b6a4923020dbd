// A study: what was swept, every measurement, the fitted models and the conclusions computed
// from them. Written as study.json (rvr-study/1, study_json.h) and study.md (study_markdown.h).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rvr/study/counted_work.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"
#include "rvr/study/memory_estimate.h"
#include "rvr/study/scene_changes.h"
#include "rvr/study/sweep_plan.h"
#include "rvr/study/system_probe.h"

namespace rvr::study {

struct MachineInfo {
  std::string cpu;
  unsigned threads = 0;
  std::string kernels;                          // which SIMD kernels ran and why
  std::map<std::string, std::string> versions;  // rvr, embree, tbb, compiler
};

// One renderer's model, fitted separately to each scene: a sphere's triangles and a soup's do
// not cost the same.
struct RendererModels {
  std::string name;
  std::string loop_order;  // "triangle-major", "pixel-major", "hybrid"
  ModelForm form = ModelForm::ZBuffer;
  std::map<std::string, ModelFit> fits;  // by scene
};

// The log-log slope of time against an axis over one decade of it (the family's N at the full
// width), or over the whole pixel sweep at one N.
struct ScalingExponent {
  std::string renderer, scene;
  std::string axis;  // the family's ("triangles", "depth") or "pixels"
  double from = 0, to = 0;
  double exponent = 0;
  double n = 0;  // the N held fixed on the pixels axis; 0 on the others
};

// Time per triangle and per primary ray at one measured point.
struct UnitCost {
  std::string renderer, scene;
  double n = 0, seconds = 0;
  double ns_per_triangle = 0, ns_per_ray = 0;
};

// A crossover's prediction checked out of sample after the fit: a point off the sweep's grid
// (a third of and three times a measured crossover; an extrapolated one at its value and three
// times it) measured in fresh sessions, its paired ratio set against what the conclusions say
// there: which renderer is faster, and what the fitted models predict for the ratio.
struct PredictionCheck {
  std::string a, b, scene, axis;
  double crossover = 0;          // the crossover's value on the axis
  bool extrapolated = false;     // the crossover lay outside the swept range
  double at = 0;                 // where the check measured: the axis value of its point
  double pixels = 0, n = 0;      // the pixel count and N of the point measured
  std::string predicted_faster;  // "" where the conclusion is that they are equal (at the value)
  std::string measured_faster;   // "" where the measured ratio is within the noise threshold
  double ratio = 0;              // measured t_a / t_b, paired
  Interval ratio_ci95;           // its hierarchical bootstrap interval
  double p = 1;                  // that it is within the noise threshold (Holm over the checks)
  double predicted_ratio = 0;    // the fitted models' t_a / t_b there (NaN: no model fits)
  Interval predicted_ci95;       // over the models' bootstrap replicates
  std::string verdict;           // "holds", "fails" or "inconclusive"
  std::string why;               // the reason, in words
};

// A hybrid's frame split into its z-buffer pass and its tracer's part, at one point.
struct PhaseSplit {
  std::string renderer, scene;
  double n = 0, pixels = 0;
  double zbuffer_seconds = 0, trace_seconds = 0;  // medians over the repetitions
  double zbuffer_share = 0;                       // zbuffer / (zbuffer + trace)
};

// A session: the level above a run's frames. In the CLI each is a fresh process (a worker
// started for it); in-process callers (Python, tests) prepare each scene afresh instead.
struct SessionInfo {
  std::string kind;       // "process" or "preparation"
  std::string study;      // the run_id of the study that ran it (several after --merge)
  SystemSnapshot system;  // the machine as the session began
};

struct StudyResult {
  std::vector<std::string> scenes;          // families: "tessphere"
  std::vector<std::string> renderers;       // in the order asked for
  std::map<std::string, std::string> axes;  // scene -> "triangles" | "depth"
  int width = 0, height = 0;
  std::string mode;
  double budget_seconds = 0, elapsed_seconds = 0;
  int repetitions = 0;         // rounds per run
  int sessions_per_point = 0;  // runs per point, each in a fresh session
  double noise_threshold = 0;  // the smallest difference called one (a ratio minus 1)
  uint64_t seed = 0;
  int bootstrap_replicates = 0;
  std::string command;  // the command line, when the caller sets it
  // Unique to one sweep (random, set when it starts): --merge refuses a study it already holds.
  std::string run_id;
  std::vector<std::string> merged_runs;  // after --merge: the run_id of every study pooled
  MachineInfo machine;
  std::vector<SessionInfo> sessions;           // Run::session indexes these
  SystemSnapshot system_before, system_after;  // the machine before and after the sweep
  std::vector<Measurement> points;
  std::vector<RendererModels> models;
  std::vector<Comparison> comparisons;  // every pair along every axis, point by point
  std::vector<Crossover> crossovers;
  std::vector<Dominance> dominance;
  std::vector<ScalingExponent> scaling;
  std::vector<UnitCost> costs;
  std::vector<PhaseSplit> splits;  // the hybrids', at the smallest and largest N at full width
  // Each renderer's preparation per point, and the frames per scene change above which a
  // renderer that builds per scene beats a z-buffer (scene_changes.h): at the full image size.
  std::vector<BuildCost> builds;
  std::vector<SceneChange> scene_changes;
  // Each family's memory, estimated before its sweep went past the probes' N, and the planned N
  // it dropped (memory_estimate.h); empty for a family that never went past them, or when the
  // sweep had no way to probe memory.
  std::vector<FamilyMemory> memory;
  // Per renderer and family: the cost model from counted work, each count's scaling with N and
  // the pixel count, and the chapter's claims checked on counts (counted_work.h).
  std::vector<WorkModel> work_models;
  std::vector<CountScaling> count_scaling;
  std::vector<CountClaim> count_claims;
  std::vector<PredictionCheck> checks;
  std::vector<Measurement> check_points;  // what the checks measured (not in the fits)
  std::vector<std::string> notes;         // what the budget cut short, and the like
  // Why the study concludes nothing (no crossover, dominance or tie, no model that fits);
  // empty when it concludes something.
  std::string no_conclusion;
  bool interrupted = false;    // the sweep was stopped (Ctrl-C) before its end
  std::optional<Shard> shard;  // the share of the planned points measured (--shard)
};

}  // namespace rvr::study
