// Weighted least squares by Householder QR (see least_squares.h).
#include "rvr/study/least_squares.h"

#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "rvr/shared/check.h"

namespace rvr::study {
namespace {

using Matrix = std::vector<std::vector<double>>;  // rows

// The weighted, column-scaled design matrix of the used columns and the weighted targets.
void weighted_system(const Matrix& x, const std::vector<double>& y, const std::vector<double>& w,
                     const std::vector<size_t>& cols, Matrix& a, std::vector<double>& b,
                     std::vector<double>& scale) {
  scale.assign(cols.size(), 0.0);
  for (size_t c : cols)
    RVR_DCHECK(x.empty() || c < x[0].size(), "a used column exists: ", c, " of ", x[0].size());
  for (const auto& row : x)
    for (size_t j = 0; j < cols.size(); ++j) scale[j] = std::max(scale[j], std::fabs(row[cols[j]]));
  for (double& s : scale) s = s > 0 ? s : 1.0;
  a.assign(x.size(), std::vector<double>(cols.size()));
  b.resize(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    double sw = std::sqrt(w[i]);
    for (size_t j = 0; j < cols.size(); ++j) a[i][j] = sw * x[i][cols[j]] / scale[j];
    b[i] = sw * y[i];
  }
}

// Householder QR in place: a becomes R in its top rows, b becomes Qᵀb. False when a column is
// (nearly) dependent on the ones before it.
bool householder(Matrix& a, std::vector<double>& b) {
  const size_t m = a.size(), k = a[0].size();
  RVR_DCHECK(m >= k && b.size() == m, "QR of a tall system: ", m, " rows, ", k, " columns, ",
             b.size(), " targets");
  std::vector<double> column_norm(k, 0.0);
  for (size_t j = 0; j < k; ++j)
    for (size_t i = 0; i < m; ++i) column_norm[j] += a[i][j] * a[i][j];
  for (size_t j = 0; j < k; ++j) {
    double norm = 0;
    for (size_t i = j; i < m; ++i) norm += a[i][j] * a[i][j];
    // What is left of the column once the ones before it are taken out: nothing, or rounding.
    if (!(norm > 1e-20 * column_norm[j])) return false;
    norm = std::sqrt(norm);
    double alpha = a[j][j] > 0 ? -norm : norm;
    std::vector<double> v(m, 0.0);
    for (size_t i = j; i < m; ++i) v[i] = a[i][j];
    v[j] -= alpha;
    double vv = 0;
    for (size_t i = j; i < m; ++i) vv += v[i] * v[i];
    if (vv == 0) continue;
    for (size_t c = j; c < k; ++c) {
      double dot = 0;
      for (size_t i = j; i < m; ++i) dot += v[i] * a[i][c];
      for (size_t i = j; i < m; ++i) a[i][c] -= 2 * dot / vv * v[i];
    }
    double dot = 0;
    for (size_t i = j; i < m; ++i) dot += v[i] * b[i];
    for (size_t i = j; i < m; ++i) b[i] -= 2 * dot / vv * v[i];
  }
  return true;
}

}  // namespace

Expected<std::vector<double>> weighted_least_squares(const Matrix& x, const std::vector<double>& y,
                                                     const std::vector<double>& w,
                                                     const std::vector<bool>& use) {
  std::vector<size_t> cols;
  for (size_t j = 0; j < use.size(); ++j)
    if (use[j]) cols.push_back(j);
  if (cols.empty() || x.size() < cols.size())
    return bad_input("least squares: " + std::to_string(x.size()) + " points for " +
                     std::to_string(cols.size()) + " coefficients");
  RVR_CHECK(y.size() == x.size() && w.size() == x.size(), "least squares: ", x.size(), " rows, ",
            y.size(), " targets, ", w.size(), " weights");
  for (const auto& row : x)
    RVR_CHECK(row.size() == use.size(), "least squares: a row of ", row.size(), " features for ",
              use.size(), " coefficients");
  Matrix a;
  std::vector<double> b, scale;
  weighted_system(x, y, w, cols, a, b, scale);
  if (!householder(a, b)) return bad_input("least squares: the model's terms are not independent");
  std::vector<double> beta(cols.size());
  for (size_t j = cols.size(); j-- > 0;) {
    double s = b[j];
    for (size_t c = j + 1; c < cols.size(); ++c) s -= a[j][c] * beta[c];
    RVR_DCHECK(a[j][j] != 0.0, "householder() refuses dependent columns");
    beta[j] = s / a[j][j];
  }
  std::vector<double> out(use.size(), 0.0);
  for (size_t j = 0; j < cols.size(); ++j) out[cols[j]] = beta[j] / scale[j];
  return out;
}

}  // namespace rvr::study
