// R², the largest relative residual and the leave-one-out error of a fit (see fit_quality.h).
#include "rvr/study/fit_quality.h"

#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "rvr/core/expected.h"
#include "rvr/study/fit.h"
#include "rvr/study/measurement.h"

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

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) s += a[i] * b[i];
  return s;
}

}  // namespace

FitQuality leave_one_out(const std::vector<std::vector<double>>& rows,
                         const std::vector<double>& times, const std::vector<bool>& use) {
  FitQuality q;
  std::vector<double> errors;
  for (size_t i = 0; i < rows.size(); ++i) {
    std::vector<std::vector<double>> rest;
    std::vector<double> rest_times;
    for (size_t j = 0; j < rows.size(); ++j)
      if (j != i) {
        rest.push_back(rows[j]);
        rest_times.push_back(times[j]);
      }
    Expected<std::vector<double>> c = fit_rows(rest, rest_times, use);
    if (!c) {
      q.loo_median_rel_error = q.loo_mean_rel_error = std::numeric_limits<double>::infinity();
      return q;
    }
    errors.push_back(std::fabs(times[i] - dot(rows[i], *c)) / times[i]);
  }
  double sum = 0;
  for (double e : errors) sum += e;
  q.loo_mean_rel_error = errors.empty() ? 0 : sum / double(errors.size());
  q.loo_median_rel_error = median(errors);
  return q;
}

FitQuality fit_quality(const std::vector<std::vector<double>>& rows,
                       const std::vector<double>& times, const std::vector<double>& coefficients,
                       const std::vector<bool>& use) {
  FitQuality q = leave_one_out(rows, times, use);
  std::vector<double> model;
  model.reserve(rows.size());
  for (const std::vector<double>& row : rows) model.push_back(dot(row, coefficients));
  q.r2 = weighted_r2(times, model);
  for (size_t i = 0; i < rows.size(); ++i)
    q.max_rel_residual = std::max(q.max_rel_residual, std::fabs(times[i] - model[i]) / times[i]);
  return q;
}

}  // namespace rvr::study
