// Where two renderers' measured curves cross along the swept axis, with a 95% interval from
// the bootstrap over repetitions; or which one wins over the whole range, and by how much.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"

namespace rvr::study {

// The name of the pixel-count axis; the others are the families' N ("triangles", "depth").
inline constexpr const char* kPixelsAxis = "pixels";

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
};

// Neither curve crosses the other over the swept range.
struct Dominance {
  std::string faster, slower, scene, axis;
  double min_ratio = 0;  // the slower's time over the faster's, at its smallest over the range
  double at = 0;         // where that smallest ratio is
  double pixels = 0;
  double n = 0;  // as in Crossover
  double range_low = 0, range_high = 0;
};

struct CurveComparison {
  // One per change of which renderer is faster beyond the timing noise, along the axis.
  std::vector<Crossover> crossovers;
  std::optional<Dominance> dominance;  // when there is none
  bool tie = false;                    // neither: no point shows a difference beyond the noise
};

// Compares a's and b's medians at the axis values both measured (points matched by n and pixel
// count; a and b each one renderer's points of one scene along one axis: at one pixel count
// along N, or at one N along "pixels"). Only changes the timing noise cannot explain count: a
// point shows a renderer faster when the 95% interval of log(t_a / t_b) over the bootstrap
// replicates excludes 0, and a crossing lies between two such points of opposite signs, where
// log(t_a / t_b) changes sign, placed by linear interpolation of it in the log of the axis.
// Each bootstrap replicate resamples every point's repetitions and takes the crossing nearest
// the measured one.
CurveComparison compare_curves(const std::vector<Measurement>& a, const std::vector<Measurement>& b,
                               const std::string& axis, const BootstrapOptions& boot);

// Where the fitted models cross outside [low, high] (searched up to 1000× beyond either end),
// when both fit and one does: the crossover reported as outside the swept range.
std::optional<double> extrapolated_crossing(const ModelFit& fa, const ModelFit& fb, double pixels,
                                            double low, double high);

}  // namespace rvr::study
