// One measured point of a study: a renderer's frames of one scene size, timed in several runs.
// Variation arises at three levels, and a point keeps each: the run (a fresh process, or at
// least a fresh preparation of the scene: memory layout, page placement, the BVH built again),
// the frame within a run, and the point itself (a scene size that happens to suit one renderer:
// seen only against its neighbours, see trend.h).
#pragma once

#include <stddef.h>

#include <map>
#include <string>
#include <vector>

namespace rvr::study {

// The frames of one point timed in one session (a process or a fresh preparation: study.h),
// in rounds: in each round every renderer of the study renders one frame, in a random order.
struct Run {
  int session = 0;              // index into StudyResult::sessions
  double prepare_seconds = 0;   // preparing the renderer for this scene (the BVH built...)
  std::vector<double> seconds;  // one per round
  std::vector<int> order;       // the renderer's position in each round
  // Per round, the seconds of each phase the renderer reports: the hybrids' "zbuffer" and
  // "trace" passes (RenderOutput::stats time.zbuffer, time.trace); empty for the others.
  std::map<std::string, std::vector<double>> phases;
  // The reference frame timed between the rounds, at its slowest, over its quickest in the
  // family so far: how much busier the machine was than at its quietest (run_study.h).
  double reference_ratio = 0;
  bool busy = false;  // reference_ratio over kBusyRatio, or the system probe saw other work
};

// The colour error of a renderer's frame where one effect acts, against the tracer's frame of
// the same point (compare's effect_errors: the mask from the tracer's ray tree). Exact and
// machine-independent, like the counters: the same in every run.
struct PointEffectError {
  std::string effect;  // "reflection", "refraction", "lens", "csg"
  double pixels = 0;   // the effect's mask
  double rmse = 0;
  double psnr_db = 0;  // +inf when identical
  double ssim = 1;     // the mean of the SSIM map over the mask
};

struct Measurement {
  std::string renderer;  // "softraster"
  std::string scene;     // the family: "tessphere"
  double scene_n = 0;    // the N of builtin:<scene>:N
  double n = 0;          // the swept axis' value: triangles (or occluders' depth)
  double pixels = 0;     // width x height: primary rays per frame
  int width = 0, height = 0;
  std::vector<Run> runs;
  // The renderer's own count of the work of one frame (RenderOutput::stats without times and
  // memory): "triangles.setup", "fragments.generated", "rays.primary", "bvh.nodes_visited", ...
  // Exact and machine-independent: the same in every run.
  std::map<std::string, double> counters;
  // In full mode, when the study holds raytrace: the error of this renderer's frame in each
  // effect's mask against raytrace's frame of the point (empty for raytrace itself, and for
  // effects no pixel of the point shows).
  std::vector<PointEffectError> effect_errors;

  // Every run measured while the machine was busy with something else.
  bool busy() const;
  size_t frames() const;  // repetitions over every run
};

// A run whose reference frame ran this much slower than its quickest was measured on a
// machine busy with something else.
constexpr double kBusyRatio = 1.3;

// The median of `values` (the mean of the middle two for an even count); 0 for none.
double median(std::vector<double> values);

// The Harrell–Davis estimate of the median: a weighted mean of the sorted values, value i
// weighted by the chance that the median of a resample falls on it (the Beta((n+1)/2,
// (n+1)/2) mass over [(i−1)/n, i/n]). The bootstrap of a sample median of 5 repetitions is
// some 35% too wide in variance, that of this estimate ~8%.
double hd_median(const std::vector<double>& values);

// hd_median's weights for n values, and the estimate from them (values in any order).
std::vector<double> hd_weights(size_t n);
double hd_median(std::vector<double> values, const std::vector<double>& weights);

// The runs a point's time is taken from: its quiet runs, or every run when none was quiet.
std::vector<const Run*> timed_runs(const Measurement& m);

// A point's time as the study uses it: the geometric mean over timed_runs of each run's
// hd_median (each run one sample of the process level, whatever its number of frames).
double typical_seconds(const Measurement& m);

// The sample median of every repetition of the timed runs.
double median_seconds(const Measurement& m);

// Median absolute deviation of the timed runs' repetitions, relative to their median.
double relative_mad(const Measurement& m);

// Every repetition of the timed runs, run after run.
std::vector<double> all_seconds(const Measurement& m);

}  // namespace rvr::study
