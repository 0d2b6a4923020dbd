// Two renderers compared along one axis: at each point the paired ratio of their frame times,
// the trend through it and its neighbours (trend.h), and whether that trend shows one renderer
// faster beyond the noise threshold, corrected for testing every point of the sweep (Holm).
// A crossover needs two consecutive significant points on each side; otherwise one renderer is
// faster where significant, or the two are tied within the noise.
#pragma once

#include <stddef.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"

namespace rvr::study {

// The name of the pixel-count axis; the others are the families' N ("triangles", "depth").
inline constexpr const char* kPixelsAxis = "pixels";

// The family-wise error rate the points of one comparison are tested at, together.
constexpr double kFamilyAlpha = 0.05;

// The fewest points a comparison is drawn from: fewer cannot tell a trend from the noise
// between points.
constexpr size_t kMinComparedPoints = 4;

// How a comparison judges its points.
struct CompareOptions {
  BootstrapOptions boot;
  // A renderer is faster only by a ratio beyond 1 + noise_threshold.
  double noise_threshold = 0.03;
};

// One point of a comparison.
struct PointComparison {
  double at = 0;     // the axis value
  double ratio = 0;  // t_a / t_b measured there, paired round by round
  double trend = 0;  // t_a / t_b of the trend through it and its neighbours
  Interval ci95;     // of the trend's ratio, this point alone (not corrected for the others)
  double p = 1;      // Holm-adjusted: that the trend's ratio is within the noise threshold
  int faster = 0;    // −1: a faster beyond the threshold, significantly; +1: b; 0: neither
};

// A pair of renderers along one axis: every point judged.
struct Comparison {
  std::string a, b, scene, axis;
  double pixels = 0;  // the pixel count held along N; 0 on the pixels axis
  double n = 0;       // the N held along pixels; 0 on the others
  std::vector<PointComparison> points;
  // The spread of log(t_a / t_b) between neighbouring points beyond what their runs show, and
  // the residual degrees of freedom of the trend: what the tests' t distribution has.
  double point_noise = 0, dof = 0;
  std::string inconclusive;  // why nothing is concluded from it; "" otherwise
};

struct Crossover {
  std::string a, b, scene, axis;
  double value = 0;  // the axis value where t_a = t_b
  // 95% interval; −inf / +inf when over 2.5% of the replicates put it below / above the range.
  Interval ci95;
  double pixels = 0;                     // the pixel count held fixed (axis "triangles" or "depth")
  double n = 0;                          // the axis value held fixed when the axis is "pixels"
  bool a_faster_below = true;            // a is the faster one below `value`
  bool measured = true;                  // false: the fitted models', outside the swept range
  double range_low = 0, range_high = 0;  // the swept axis range
  // The significant points on each side: how many, and the nearest one's trend ratio (the
  // slower's time over the faster's).
  size_t below_points = 0, above_points = 0;
  double below_ratio = 0, above_ratio = 0;
  // A prediction check at or near it measured the opposite, significantly: it is demoted.
  bool contradicted = false;
};

// Neither curve crosses the other over the swept range.
struct Dominance {
  std::string faster, slower, scene, axis;
  double min_ratio =
      0;          // the slower's time over the faster's, smallest over the significant points
  double at = 0;  // where that smallest ratio is
  double pixels = 0;
  double n = 0;  // as in Crossover
  double range_low = 0, range_high = 0;
  size_t significant = 0, points = 0;  // significant points (all the faster's) of all compared
  double significant_low = 0, significant_high = 0;  // the range they span
  // Points where the slower renderer measured faster (its paired ratio below 1), significantly
  // or not, in increasing axis value.
  std::vector<double> contrary;
  std::vector<double> contrary_ratios;  // the faster's time over the slower's there (> 1)
};

struct CurveComparison {
  Comparison comparison;
  // One per change of which renderer is faster beyond the noise threshold, along the axis.
  std::vector<Crossover> crossovers;
  std::optional<Dominance> dominance;  // when there is none
  bool tie = false;                    // enough points, none beyond the threshold
};

// Compares a's and b's points at the axis values both measured (matched by N and pixel count;
// a and b each one renderer's points of one scene along one axis). See the top of this file.
CurveComparison compare_curves(const std::vector<Measurement>& a, const std::vector<Measurement>& b,
                               const std::string& axis, const CompareOptions& options);

// Where the fitted models cross outside [low, high] (searched up to 1000× beyond either end),
// when both fit and one does: the crossover reported as outside the swept range.
std::optional<double> extrapolated_crossing(const ModelFit& fa, const ModelFit& fb, double pixels,
                                            double low, double high);

// Holm's step-down adjustment of p-values (same order as given, each at most 1).
std::vector<double> holm_adjusted(const std::vector<double>& p);

}  // namespace rvr::study
