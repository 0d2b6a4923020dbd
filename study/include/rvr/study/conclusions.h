// The conclusions computed from a study's measurements: each renderer's model per scene, the
// crossover (or the winner over the whole range) of every pair of loop orders, scaling
// exponents per decade and time per triangle and per ray.
#pragma once

#include <string>
#include <vector>

#include "rvr/study/bootstrap.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/measurement.h"
#include "rvr/study/study.h"

namespace rvr::study {

// Whether the study compares two renderers: of different loop orders, or one renderer and its
// variant (softraster and softraster_nohiz: what hierarchical z saves).
bool compared_pair(const std::string& a, const std::string& b);

// The model form of a renderer in the table, by its loop order.
ModelForm model_form_of(const std::string& renderer);

// The least-squares slope of log t against log x over the points with x in [from, to], x their
// N, or their pixel count when `axis` is "pixels"; NaN with fewer than two distinct x.
double loglog_slope(const std::vector<Measurement>& points, double from, double to,
                    const std::string& axis = "triangles");

// Whether `note` is one conclude() adds (a tie), not one of the sweep's: a study read back drops
// these, for conclude() to add them again.
bool is_conclusion_note(const std::string& note);

// Fills result.models, crossovers, dominance, scaling, costs, splits, builds and scene_changes
// from result.points.
void conclude(StudyResult& result, const BootstrapOptions& boot);

}  // namespace rvr::study
