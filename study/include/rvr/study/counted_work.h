// Cost models from counted work, and the counts' own scaling. Every point records the
// renderer's count of the work of one frame (Measurement::counters: triangles set up, fragments
// tested, rays by kind, BVH nodes visited, ...). Two things follow from them:
//   - a work model: the frame time as a constant plus a non-negative unit cost per counted
//     item, t = u0 + Σ u_k·count_k, fitted to all of a renderer's points of a family (the sweep
//     along N and the pixel sweep, so that work growing with the pixels is told from work
//     growing with N) as fit.h fits the formula models, with the same intervals;
//   - how each count scales with N and with the pixel count, and the chapter's claims checked on
//     counts rather than seconds (BVH nodes visited per ray against log2 N, the z-buffer's
//     fragments per pixel against depth complexity, triangles set up against N). Counts are
//     exact and the same on every machine: these carry no interval.
#pragma once

#include <stddef.h>

#include <string>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"

namespace rvr::study {

// A count a work model may use, and the work it counts (docs/cli.md lists the same).
struct WorkCounter {
  const char* name;    // a key of Measurement::counters, or "pixels" (Measurement::pixels)
  const char* counts;  // the work, in words
};

// The counts a loop order's work model draws from, in order: a count that is absent, the same
// at every point, or (nearly) a combination of the ones before it is left out, so the first of
// two proportional counts is the one kept.
const std::vector<WorkCounter>& work_counters(ModelForm form);

// The value of `counter` at a point: Measurement::pixels for "pixels", else its counter (NaN
// when the point has none).
double count_of(const Measurement& m, const std::string& counter);

// A count left out of a work model, and why.
struct LeftOutCounter {
  std::string counter, why;
};

struct WorkModel {
  std::string renderer, scene;
  // The constant ("frame", seconds) first, then one per count kept (seconds per item); each
  // Coefficient::name is the count's name.
  std::vector<Coefficient> terms;
  std::vector<std::string> counts;  // what each term counts, in words (terms[0]: the frame)
  std::vector<LeftOutCounter> left_out;
  double r2 = 0, max_rel_residual = 0, loo_rel_error = 0;
  double misfit = 0, repetition_noise = 0;  // as in ModelFit
  size_t points = 0;
  bool fits = false;
  std::string verdict;
  // Each bootstrap replicate's terms, for intervals of what the model predicts. Not written to
  // study.json.
  std::vector<std::vector<double>> replicates;
};

// A count is left out when the counts kept before it explain it this well: R² of its weighted
// (1/t²) least-squares fit on them, the constant included (a variance inflation of 1000).
constexpr double kCollinearR2 = 0.999;

// A count that is non-zero at fewer points is left out: leaving one of them out of the fit (the
// leave-one-out error) would leave its cost undetermined.
constexpr size_t kMinCountedPoints = 3;

// The work model of one renderer's points of one family, with the counts of `form`.
WorkModel fit_work_model(const std::string& renderer, ModelForm form,
                         const std::vector<Measurement>& points, const BootstrapOptions& boot,
                         const FitThresholds& limits = {});

// The time the work model predicts for a point (NaN when it lacks one of the counts).
double predict_work_seconds(const WorkModel& model, const Measurement& point);

// How one count grows along an axis: the least-squares line of log count against log axis.
struct CountScaling {
  std::string renderer, scene, counter;
  std::string axis;  // the family's ("triangles", "depth") or "pixels"
  double n = 0;      // on the pixels axis, the N held; 0 on the others
  double from = 0, to = 0;
  double exponent = 0;  // the slope: count ∝ axis^exponent
  double r2 = 0;        // of that line: how well one power describes the counts
  size_t points = 0;
};

// Every count of `form` a renderer reports (not zero at every point), against N over the points
// at `full_pixels` and against the pixel count at each N measured at several pixel counts.
std::vector<CountScaling> count_scaling(const std::string& renderer, ModelForm form,
                                        const std::string& scene, const std::string& axis,
                                        double full_pixels, const std::vector<Measurement>& points);

// One of the chapter's claims checked on counts: a quantity derived from them, fitted as
// intercept + slope·x (least squares, unweighted), x a function of the family's axis.
struct CountClaim {
  std::string renderer, scene;
  std::string claim;     // "nodes_per_ray", "fragments_per_pixel", "triangles_set_up"
  std::string quantity;  // "bvh.nodes_visited / rays", in words of the counters
  std::string against;   // "log2 N", "D", "N"
  double intercept = 0, slope = 0;
  double r2 = 0;            // of the line: how linear the quantity is in x
  double exponent = 0;      // the log-log slope of the quantity against the axis
  double from = 0, to = 0;  // the axis' range
  size_t points = 0;
};

// The claims that apply to a renderer's points of a family at `full_pixels`: BVH nodes visited
// per ray traced against log2 N (tracers, along triangles), z-buffer fragments generated per
// pixel against depth (z-buffers and hybrids, along depth), triangles set up against N
// (z-buffers and hybrids, along triangles). None without the counts or two distinct N.
std::vector<CountClaim> count_claims(const std::string& renderer, ModelForm form,
                                     const std::string& scene, const std::string& axis,
                                     double full_pixels, const std::vector<Measurement>& points);

}  // namespace rvr::study
