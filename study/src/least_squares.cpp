// Weighted least squares by Householder QR, and its non-negative form by Lawson–Hanson (see
// least_squares.h).
#include "rvr/study/least_squares.h"

#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "rvr/core/check.h"

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

// The least-squares solution of a·β ≈ b over the columns `cols` of a (a tall system), or false
// when they are (nearly) dependent.
bool solve_columns(const Matrix& a, const std::vector<double>& b, const std::vector<size_t>& cols,
                   std::vector<double>& beta) {
  Matrix sub(a.size(), std::vector<double>(cols.size()));
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < cols.size(); ++j) sub[i][j] = a[i][cols[j]];
  std::vector<double> qb = b;
  if (!householder(sub, qb)) return false;
  beta.assign(cols.size(), 0.0);
  for (size_t j = cols.size(); j-- > 0;) {
    double s = qb[j];
    for (size_t c = j + 1; c < cols.size(); ++c) s -= sub[j][c] * beta[c];
    RVR_DCHECK(sub[j][j] != 0.0, "householder() refuses dependent columns");
    beta[j] = s / sub[j][j];
  }
  return true;
}

// The columns used, or an error when there are too few rows for them.
Expected<std::vector<size_t>> used_columns(const Matrix& x, const std::vector<double>& y,
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
  return cols;
}

const char* const kDependent = "least squares: the model's terms are not independent";

// Lawson–Hanson on the scaled system a·β ≈ b (columns 0 .. k−1): β ≥ 0 minimizing the residual.
// The columns are independent (the caller checked), so every passive set's subproblem is
// solvable; the loop ends in finitely many steps, and a cap guards against rounding cycling.
std::vector<double> lawson_hanson(const Matrix& a, const std::vector<double>& b) {
  const size_t m = a.size(), k = a[0].size();
  std::vector<double> beta(k, 0.0);
  std::vector<bool> passive(k, false);
  double b_norm = 0;
  for (double v : b) b_norm += v * v;
  // Columns have unit largest entry: a gradient below this is rounding, not a descent.
  const double tolerance = 1e-12 * double(m) * std::sqrt(b_norm + 1e-300);
  auto gradient = [&]() {
    std::vector<double> residual = b;
    for (size_t i = 0; i < m; ++i)
      for (size_t j = 0; j < k; ++j) residual[i] -= a[i][j] * beta[j];
    std::vector<double> g(k, 0.0);
    for (size_t j = 0; j < k; ++j)
      for (size_t i = 0; i < m; ++i) g[j] += a[i][j] * residual[i];
    return g;
  };
  for (size_t outer = 0; outer < 3 * k + 3; ++outer) {
    const std::vector<double> g = gradient();
    size_t enter = k;
    for (size_t j = 0; j < k; ++j)
      if (!passive[j] && g[j] > tolerance && (enter == k || g[j] > g[enter])) enter = j;
    if (enter == k) break;
    passive[enter] = true;
    for (size_t inner = 0; inner < 3 * k + 3; ++inner) {
      std::vector<size_t> cols;
      for (size_t j = 0; j < k; ++j)
        if (passive[j]) cols.push_back(j);
      std::vector<double> z;
      if (!solve_columns(a, b, cols, z)) {
        // Rounding made the passive columns dependent: the entering one adds nothing.
        passive[enter] = false;
        break;
      }
      bool feasible = true;
      for (double v : z) feasible = feasible && v > 0;
      if (feasible) {
        for (size_t c = 0; c < cols.size(); ++c) beta[cols[c]] = z[c];
        break;
      }
      // Step from β towards z as far as every coefficient stays non-negative: the one that
      // reaches 0 first (and any that land within rounding of it) leaves the passive set.
      double step = 1.0, largest = 0;
      size_t blocking = k;
      for (size_t c = 0; c < cols.size(); ++c)
        if (z[c] <= 0) {
          const double s = beta[cols[c]] / (beta[cols[c]] - z[c]);
          if (blocking == k || s < step) step = s, blocking = c;  // s is in [0, 1]
        }
      for (size_t c = 0; c < cols.size(); ++c) {
        double& v = beta[cols[c]];
        v += step * (z[c] - v);
        largest = std::max(largest, std::fabs(v));
      }
      if (blocking < k) beta[cols[blocking]] = 0;
      for (size_t c = 0; c < cols.size(); ++c)
        if (beta[cols[c]] <= 1e-14 * largest) beta[cols[c]] = 0, passive[cols[c]] = false;
    }
  }
  return beta;
}

}  // namespace

Expected<std::vector<double>> weighted_least_squares(const Matrix& x, const std::vector<double>& y,
                                                     const std::vector<double>& w,
                                                     const std::vector<bool>& use) {
  RVR_TRY_ASSIGN(cols, used_columns(x, y, w, use));
  Matrix a;
  std::vector<double> b, scale, beta;
  weighted_system(x, y, w, *cols, a, b, scale);
  std::vector<size_t> all(cols->size());
  for (size_t j = 0; j < all.size(); ++j) all[j] = j;
  if (!solve_columns(a, b, all, beta)) return bad_input(kDependent);
  std::vector<double> out(use.size(), 0.0);
  for (size_t j = 0; j < cols->size(); ++j) out[(*cols)[j]] = beta[j] / scale[j];
  return out;
}

Expected<std::vector<double>> nonnegative_least_squares(const Matrix& x,
                                                        const std::vector<double>& y,
                                                        const std::vector<double>& w,
                                                        const std::vector<bool>& use) {
  RVR_TRY_ASSIGN(cols, used_columns(x, y, w, use));
  Matrix a;
  std::vector<double> b, scale;
  weighted_system(x, y, w, *cols, a, b, scale);
  {
    Matrix r = a;
    std::vector<double> qb = b;
    if (!householder(r, qb)) return bad_input(kDependent);
  }
  const std::vector<double> beta = lawson_hanson(a, b);
  std::vector<double> out(use.size(), 0.0);
  for (size_t j = 0; j < cols->size(); ++j) out[(*cols)[j]] = beta[j] / scale[j];
  return out;
}

}  // namespace rvr::study
