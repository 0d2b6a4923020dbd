// R², the largest relative residual and the leave-one-out error of a fit (see fit_quality.h).
#include "rvr/study/fit_quality.h"

#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "rvr/shared/expected.h"
#include "rvr/study/fit.h"

namespace rvr::study {
namespace {

double weighted_r2(const std::vector<double>& t, const std::vector<double>& model) {
  double sw = 0, swt = 0;
  for (double v : t) {
    sw += 1 / (v * v);
    swt += v / (v * v);
  }
  const double mean = swt / sw;
  double residual = 0, total = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    double w = 1 / (t[i] * t[i]);
    residual += w * (t[i] - model[i]) * (t[i] - model[i]);
    total += w * (t[i] - mean) * (t[i] - mean);
  }
  return total > 0 ? 1 - residual / total : (residual == 0 ? 1.0 : 0.0);
}

}  // namespace

FitQuality leave_one_out(const CostModel& model, const std::vector<Measurement>& points,
                         const std::vector<double>& medians, const std::vector<bool>& use) {
  FitQuality q;
  std::vector<double> errors;
  for (size_t i = 0; i < points.size(); ++i) {
    std::vector<Measurement> rest;
    std::vector<double> rest_medians;
    for (size_t j = 0; j < points.size(); ++j)
      if (j != i) {
        rest.push_back(points[j]);
        rest_medians.push_back(medians[j]);
      }
    Expected<std::vector<double>> c = fit_coefficients(model, rest, rest_medians, use);
    if (!c) {
      q.loo_median_rel_error = q.loo_mean_rel_error = std::numeric_limits<double>::infinity();
      return q;
    }
    errors.push_back(std::fabs(medians[i] - predict(model, *c, points[i].pixels, points[i].n)) /
                     medians[i]);
  }
  double sum = 0;
  for (double e : errors) sum += e;
  q.loo_mean_rel_error = errors.empty() ? 0 : sum / double(errors.size());
  q.loo_median_rel_error = median(errors);
  return q;
}

FitQuality fit_quality(const CostModel& cost_model, const std::vector<Measurement>& points,
                       const std::vector<double>& medians, const std::vector<double>& coefficients,
                       const std::vector<bool>& use) {
  FitQuality q = leave_one_out(cost_model, points, medians, use);
  std::vector<double> model;
  model.reserve(points.size());
  for (const Measurement& p : points)
    model.push_back(predict(cost_model, coefficients, p.pixels, p.n));
  q.r2 = weighted_r2(medians, model);
  for (size_t i = 0; i < points.size(); ++i)
    q.max_rel_residual =
        std::max(q.max_rel_residual, std::fabs(medians[i] - model[i]) / medians[i]);
  return q;
}

}  // namespace rvr::study
