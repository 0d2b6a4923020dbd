#include "ssim.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "rvr/core/check.h"

namespace rvr {

float luminance(const glm::vec3& c) {
  auto cl = [](float v) { return v > 0.0f ? std::min(v, 1.0f) : 0.0f; };  // NaN -> 0
  return 0.2126f * cl(c.r) + 0.7152f * cl(c.g) + 0.0722f * cl(c.b);
}

std::vector<double> ssim_map(const std::vector<float>& ya, const std::vector<float>& yb, int w,
                             int h) {
  if (w <= 0 || h <= 0) return {};
  RVR_CHECK(ya.size() == size_t(w) * size_t(h) && yb.size() == ya.size(),
            "one luminance per pixel of the ", w, "x", h, " image: ", ya.size(), " and ",
            yb.size());
  constexpr int R = 5;
  std::array<double, 2 * R + 1> g{};
  for (int k = -R; k <= R; ++k) g[k + R] = std::exp(-double(k * k) / (2.0 * 1.5 * 1.5));

  // Horizontal pass of the five moments (a, b, a^2, b^2, ab) of one row, into a ring of 11 rows.
  constexpr int kMoments = 5;
  const int ring = 2 * R + 1;
  std::vector<double> hbuf(size_t(ring) * kMoments * w);
  auto hrow = [&](int y) -> double* { return &hbuf[size_t(y % ring) * kMoments * w]; };
  auto horizontal = [&](int y) {
    double* out = hrow(y);
    const float* ra = &ya[size_t(y) * w];
    const float* rb = &yb[size_t(y) * w];
    for (int x = 0; x < w; ++x) {
      double s[kMoments] = {0, 0, 0, 0, 0}, wsum = 0;
      int k0 = std::max(-R, -x), k1 = std::min(R, w - 1 - x);
      for (int k = k0; k <= k1; ++k) {
        double wt = g[k + R], a = ra[x + k], b = rb[x + k];
        wsum += wt;
        s[0] += wt * a;
        s[1] += wt * b;
        s[2] += wt * a * a;
        s[3] += wt * b * b;
        s[4] += wt * a * b;
      }
      for (int m = 0; m < kMoments; ++m) out[size_t(m) * w + x] = s[m] / wsum;
    }
  };

  const double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03;
  std::vector<double> map(size_t(w) * size_t(h));
  int done = 0;  // rows [0, done) have been filtered horizontally
  std::vector<double> s(size_t(kMoments) * w);
  for (int y = 0; y < h; ++y) {
    while (done < std::min(h, y + R + 1)) horizontal(done++);
    std::fill(s.begin(), s.end(), 0.0);
    int k0 = std::max(-R, -y), k1 = std::min(R, h - 1 - y);
    double wsum = 0;
    for (int k = k0; k <= k1; ++k) {
      double wt = g[k + R];
      wsum += wt;
      const double* row = hrow(y + k);
      for (size_t i = 0; i < s.size(); ++i) s[i] += wt * row[i];
    }
    double* out = &map[size_t(y) * size_t(w)];
    for (int x = 0; x < w; ++x) {
      double ma = s[x] / wsum, mb = s[size_t(w) + x] / wsum;
      double va = std::max(0.0, s[2 * size_t(w) + x] / wsum - ma * ma);
      double vb = std::max(0.0, s[3 * size_t(w) + x] / wsum - mb * mb);
      double cov = s[4 * size_t(w) + x] / wsum - ma * mb;
      out[x] = ((2 * ma * mb + C1) * (2 * cov + C2)) / ((ma * ma + mb * mb + C1) * (va + vb + C2));
    }
  }
  return map;
}

double mean_ssim(const std::vector<double>& map, int w) {
  if (w <= 0 || map.empty()) return 1.0;
  // Row by row, as the sum of each row and then of the rows.
  double total = 0.0;
  for (size_t row = 0; row < map.size(); row += size_t(w)) {
    double row_total = 0.0;
    for (size_t x = 0; x < size_t(w); ++x) row_total += map[row + x];
    total += row_total;
  }
  return total / double(map.size());
}

}  // namespace rvr
