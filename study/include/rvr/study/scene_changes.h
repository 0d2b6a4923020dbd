// What a renderer builds per scene, and what it costs a scene that changes. The tracers (and
// the hybrids, whose tracer needs it) build a BVH over the scene's triangles before their first
// frame (Run::prepare_seconds, every run); a z-buffer builds nothing: everything it does per
// scene (transforming and setting up every triangle) it does again in every frame, so its
// preparation is the making of the renderer alone. A scene that changes every k frames (an
// animation, an edit) pays the build again each time: a frame then costs
// t_frame + t_prepare / k, and a renderer that builds wins against one that does not only
// for k above
//     k* = (prepare_b − prepare_a) / (frame_a − frame_b)
// where its frames are the faster (frame_a > frame_b), and never where they are not.
#pragma once

#include <stddef.h>

#include <string>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/measurement.h"

namespace rvr::study {

// One renderer's preparation at one point: over its runs (one preparation each).
struct BuildCost {
  std::string renderer, scene;
  double n = 0, pixels = 0;
  double prepare_seconds = 0;  // the median over the runs
  double low = 0, high = 0;    // the quickest and the slowest run's
  double ns_per_triangle = 0;  // the median over N (the axis value), in nanoseconds
  size_t runs = 0;
};

// The frames per scene change above which renderer b (which builds per scene) costs less per
// frame than renderer a (a z-buffer), at one point.
struct SceneChange {
  std::string a, b, scene;
  double n = 0, pixels = 0;
  double frame_a = 0, frame_b = 0;      // seconds a frame (typical_seconds)
  double prepare_a = 0, prepare_b = 0;  // seconds a preparation (the mean over the runs)
  // k*: b wins for scenes that last more than this many frames; 0: b wins at every k (its
  // build no dearer, its frames faster); +inf: never (its frames are no faster).
  double frames = 0;
  Interval ci95;  // of k* over the hierarchical bootstrap (+inf ends: never, in that share)
};

// k* = (prepare_b − prepare_a) / (frame_a − frame_b) where frame_a > frame_b (at least 0);
// +inf where frame_a <= frame_b.
double frames_per_scene_change(double frame_a, double prepare_a, double frame_b, double prepare_b);

// The preparation of one measurement, over its runs; empty runs give runs = 0.
BuildCost build_cost(const Measurement& m);

// k* at the point a and b measured (same scene, N and pixels), with its 95% interval: each
// replicate draws the sessions both measured with replacement and, in each, the rounds with
// replacement (the same rounds for both: they ran interleaved), and takes each renderer's frame
// time as resample_time does (the geometric mean over the drawn sessions of each one's
// Harrell–Davis median) and its preparation as the mean over the drawn sessions.
SceneChange scene_change(const Measurement& a, const Measurement& b, const BootstrapOptions& boot);

struct StudyResult;

// Fills result.builds (every renderer's preparation at every point at the full image size) and
// result.scene_changes (every z-buffer against every renderer that builds per scene, at every N
// both measured at the full image size), from result.points.
void scene_change_conclusions(StudyResult& result, const BootstrapOptions& boot);

// The sentences of study.md's section on what is built per scene: each renderer's preparation
// at the smallest and largest N, and per pair and family where k* falls along N.
std::vector<std::string> build_sentences(const StudyResult& result);

}  // namespace rvr::study
