// The study's own test of what it concludes: every crossover measured along N is checked with
// new measurements, independent of the fit, at a third of and at three times its value.
#pragma once

#include <vector>

#include "rvr/shared/expected.h"
#include "rvr/study/run_study.h"
#include "rvr/study/study.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study {

// For each measured crossover of result.crossovers along a family's axis: the family's scene
// at the N nearest a third of and three times its value (scene N scaled from the nearest
// measured point), at full width, both renderers timed `request.repetitions` times in random
// order; the Harrell–Davis medians say which was faster. Appends to result.checks; stops when
// hooks.cancelled says so.
Status check_predictions(const StudyRequest& request, const StudyHooks& hooks,
                         const std::vector<Family>& families, StudyResult& result);

}  // namespace rvr::study
