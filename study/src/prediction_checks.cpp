// Crossovers checked at a third and three times their value (see prediction_checks.h).
#include "rvr/study/prediction_checks.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>

#include "rvr/study/bootstrap.h"
#include "rvr/study/crossover.h"
#include "rvr/study/measurement.h"

namespace rvr::study {
namespace {

constexpr double kCheckFactor = 3.0;

// The scene N whose axis value is nearest `at`: the nearest measured point's N scaled by
// at / its axis value (the families' axis grows in proportion to their N).
size_t scene_n_near(const StudyResult& r, const std::string& scene, double at) {
  const Measurement* nearest = nullptr;
  for (const Measurement& m : r.points)
    if (m.scene == scene && m.n > 0 &&
        (!nearest || std::fabs(std::log(m.n / at)) < std::fabs(std::log(nearest->n / at))))
      nearest = &m;
  if (!nearest) return 0;
  return size_t(std::max(1.0, std::round(nearest->scene_n * at / nearest->n)));
}

size_t index_of(const std::vector<std::string>& names, const std::string& name) {
  return size_t(std::find(names.begin(), names.end(), name) - names.begin());
}

// a's and b's frames at (family, n), interleaved in random order: their Harrell–Davis medians.
Expected<std::pair<double, double>> time_pair(const StudyRequest& request, const StudyHooks& hooks,
                                              const Family& family, size_t n, size_t a, size_t b,
                                              Rng& rng, double& axis_value) {
  Expected<std::unique_ptr<FrameSource>> frames = hooks.prepare(family, n, request.width);
  if (!frames) return frames.error();
  axis_value = (*frames)->axis_value();
  std::vector<double> ta, tb;
  for (int k = 0; k < request.repetitions; ++k) {
    if (hooks.cancelled && hooks.cancelled()) return internal_error("cancelled");
    const bool a_first = rng.below(2) == 0;
    for (size_t which : {a_first ? a : b, a_first ? b : a}) {
      Expected<double> t = (*frames)->time_frame(which);
      if (!t) return t.error();
      (which == a ? ta : tb).push_back(*t);
    }
  }
  return std::pair{hd_median(ta), hd_median(tb)};
}

}  // namespace

Status check_predictions(const StudyRequest& request, const StudyHooks& hooks,
                         const std::vector<Family>& families, StudyResult& result) {
  Rng rng(request.seed ^ 0x5eedc0de);
  const std::vector<Crossover> crossovers = result.crossovers;
  for (const Crossover& c : crossovers) {
    if (!c.measured || c.axis == kPixelsAxis) continue;
    auto family = std::find_if(families.begin(), families.end(),
                               [&](const Family& f) { return f.name == c.scene; });
    if (family == families.end()) continue;
    for (double factor : {1 / kCheckFactor, kCheckFactor}) {
      if (hooks.cancelled && hooks.cancelled()) return ok_status();
      size_t n = scene_n_near(result, c.scene, c.value * factor);
      if (n == 0) continue;
      if (hooks.on_progress)
        hooks.on_progress(
            fmt::format("checking {} against {} on {} at N={}", c.a, c.b, c.scene, n));
      double axis_value = 0;
      Expected<std::pair<double, double>> t =
          time_pair(request, hooks, *family, n, index_of(request.renderers, c.a),
                    index_of(request.renderers, c.b), rng, axis_value);
      if (!t) {
        if (hooks.cancelled && hooks.cancelled()) return ok_status();
        return t.error();
      }
      PredictionCheck check;
      check.a = c.a;
      check.b = c.b;
      check.scene = c.scene;
      check.axis = c.axis;
      check.crossover = c.value;
      check.at = axis_value;
      check.pixels = c.pixels;
      const bool below = axis_value < c.value;
      check.predicted_faster = below == c.a_faster_below ? c.a : c.b;
      check.measured_faster = t->first < t->second ? c.a : c.b;
      check.ratio = std::max(t->first, t->second) / std::min(t->first, t->second);
      check.holds = check.predicted_faster == check.measured_faster;
      result.checks.push_back(check);
    }
  }
  return ok_status();
}

}  // namespace rvr::study
