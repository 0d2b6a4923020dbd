// The study's test of what it concludes: every crossover (measured or extrapolated, along N
// or along the pixel count) is checked out of sample, at points off the sweep's grid measured
// in fresh sessions, independently of the points it was found from. A check can fail: a
// renderer measured significantly faster on the side the crossover gives the other, or a
// ratio outside what the fitted models predict. A failed check demotes the conclusion.
#pragma once

#include <stddef.h>

#include <string>
#include <vector>

#include "rvr/study/crossover.h"
#include "rvr/study/study.h"

namespace rvr::study {

// A point a check measures: builtin:<scene>:<scene_n> (or copies of its file) at `width`.
struct CheckPoint {
  size_t crossover = 0;  // index into StudyResult::crossovers
  std::string scene;
  size_t scene_n = 0;
  int width = 0;
};

// The points that check the study's crossovers: for a measured one, a third of and three times
// its value; for an extrapolated one, its value and three times it (beyond the range: the side
// the models predict). N by scaling the nearest measured point's scene N; along the pixel
// count, the width at the same N. Moved by 15% where that falls on a point already measured.
std::vector<CheckPoint> plan_checks(const StudyResult& r);

// Sets result.checks from result.check_points (the points measured for plan_checks(result)),
// and marks each crossover a check contradicts.
void evaluate_checks(StudyResult& result, const CompareOptions& options);

}  // namespace rvr::study
