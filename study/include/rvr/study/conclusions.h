// The conclusions computed from a study's measurements: each renderer's model per scene, the
// crossover (or the winner over the whole range) of every pair of loop orders, scaling
// exponents per decade and time per triangle and per ray.
#pragma once

#include <string>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/study.h"

namespace rvr::study {

// The model form of a renderer in the table, by its loop order.
ModelForm model_form_of(const std::string& renderer);

// The least-squares slope of log t against log x over the points with x in [from, to], x their
// N, or their pixel count when `axis` is "pixels"; NaN with fewer than two distinct x.
double loglog_slope(const std::vector<Measurement>& points, double from, double to,
                    const std::string& axis = "triangles");

// Fills result.models, crossovers, dominance, scaling and costs from result.points.
void conclude(StudyResult& result, const BootstrapOptions& boot);

}  // namespace rvr::study
