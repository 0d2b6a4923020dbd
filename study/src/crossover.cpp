// Crossovers of measured curves and their bootstrap intervals (see crossover.h).
#include "rvr/study/crossover.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rvr::study {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// a's and b's points at the axis values both have, in increasing n.
void matched(const std::vector<Measurement>& a, const std::vector<Measurement>& b,
             std::vector<Measurement>& ma, std::vector<Measurement>& mb) {
  for (const Measurement& p : a)
    for (const Measurement& q : b)
      if (p.n == q.n && p.pixels == q.pixels) {
        ma.push_back(p);
        mb.push_back(q);
      }
  std::vector<size_t> idx(ma.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(), [&](size_t i, size_t j) { return ma[i].n < ma[j].n; });
  std::vector<Measurement> sa, sb;
  for (size_t i : idx) {
    sa.push_back(ma[i]);
    sb.push_back(mb[i]);
  }
  ma = std::move(sa);
  mb = std::move(sb);
}

struct Crossing {
  double log_n;
  bool a_faster_below;
};

// Every sign change of d = log(t_a / t_b) over the points, in log n.
std::vector<Crossing> crossings(const std::vector<double>& log_n, const std::vector<double>& d) {
  std::vector<Crossing> out;
  for (size_t i = 0; i + 1 < d.size(); ++i) {
    if ((d[i] < 0) == (d[i + 1] < 0) || d[i] == 0) continue;
    double f = d[i] / (d[i] - d[i + 1]);
    out.push_back({log_n[i] + f * (log_n[i + 1] - log_n[i]), d[i] < 0});
  }
  return out;
}

std::vector<double> log_ratios(const std::vector<double>& ta, const std::vector<double>& tb) {
  std::vector<double> d;
  for (size_t i = 0; i < ta.size(); ++i) d.push_back(std::log(ta[i] / tb[i]));
  return d;
}

// The replicates' positions of the crossing `c`: the nearest of each replicate's crossings of
// the same direction, or ±inf when a replicate has none (one renderer faster everywhere).
std::vector<double> replicate_positions(const std::vector<Measurement>& a,
                                        const std::vector<Measurement>& b,
                                        const std::vector<double>& log_n, const Crossing& c,
                                        const BootstrapOptions& boot) {
  Rng rng(boot.seed);
  std::vector<double> positions;
  for (int r = 0; r < boot.replicates; ++r) {
    std::vector<double> ta = resample_medians(a, rng), tb = resample_medians(b, rng);
    std::vector<double> d = log_ratios(ta, tb);
    double best = kInf, best_distance = kInf;
    for (const Crossing& x : crossings(log_n, d))
      if (x.a_faster_below == c.a_faster_below && std::fabs(x.log_n - c.log_n) < best_distance) {
        best_distance = std::fabs(x.log_n - c.log_n);
        best = std::exp(x.log_n);
      }
    if (best_distance == kInf) {
      // a faster everywhere: a crossing where a stops being faster lies above the range.
      bool a_everywhere = d.front() < 0;
      best = a_everywhere == c.a_faster_below ? kInf : -kInf;
    }
    positions.push_back(best);
  }
  return positions;
}

Dominance dominance(const std::vector<Measurement>& a, const std::vector<Measurement>& b,
                    const std::vector<double>& d) {
  Dominance dom;
  bool a_faster = d.front() < 0;
  dom.faster = a_faster ? a[0].renderer : b[0].renderer;
  dom.slower = a_faster ? b[0].renderer : a[0].renderer;
  dom.min_ratio = kInf;
  for (size_t i = 0; i < d.size(); ++i)
    if (std::exp(std::fabs(d[i])) < dom.min_ratio) {
      dom.min_ratio = std::exp(std::fabs(d[i]));
      dom.at = a[i].n;
    }
  return dom;
}

}  // namespace

CurveComparison compare_curves(const std::vector<Measurement>& a_in,
                               const std::vector<Measurement>& b_in, const std::string& axis,
                               const BootstrapOptions& boot) {
  CurveComparison out;
  std::vector<Measurement> a, b;
  matched(a_in, b_in, a, b);
  if (a.empty()) return out;
  std::vector<double> log_n, ta, tb;
  for (size_t i = 0; i < a.size(); ++i) {
    log_n.push_back(std::log(a[i].n));
    ta.push_back(typical_seconds(a[i]));
    tb.push_back(typical_seconds(b[i]));
  }
  std::vector<double> d = log_ratios(ta, tb);
  for (const Crossing& c : crossings(log_n, d)) {
    Crossover x;
    x.a = a[0].renderer;
    x.b = b[0].renderer;
    x.scene = a[0].scene;
    x.axis = axis;
    x.value = std::exp(c.log_n);
    x.ci95 = percentile_interval(replicate_positions(a, b, log_n, c, boot));
    x.pixels = a[0].pixels;
    x.a_faster_below = c.a_faster_below;
    x.range_low = a.front().n;
    x.range_high = a.back().n;
    out.crossovers.push_back(x);
  }
  if (out.crossovers.empty()) {
    Dominance dom = dominance(a, b, d);
    dom.scene = a[0].scene;
    dom.axis = axis;
    dom.pixels = a[0].pixels;
    dom.range_low = a.front().n;
    dom.range_high = a.back().n;
    out.dominance = dom;
  }
  return out;
}

std::optional<double> extrapolated_crossing(const ModelFit& fa, const ModelFit& fb, double pixels,
                                            double low, double high) {
  if (!fa.fits || !fb.fits) return std::nullopt;
  std::vector<double> ca = coefficient_values(fa), cb = coefficient_values(fb);
  // The models' log ratio; a folded b·P is part of a, so it is evaluated at the study's P.
  auto d = [&](double log_n) {
    double n = std::exp(log_n);
    double ta = predict(fa.form, ca, pixels, n), tb = predict(fb.form, cb, pixels, n);
    return ta > 0 && tb > 0 ? std::log(ta / tb) : std::numeric_limits<double>::quiet_NaN();
  };
  // Search outward from each end in steps of a quarter decade, then bisect the bracket.
  const double step = std::log(10.0) / 4;
  for (int side : {+1, -1}) {
    double x0 = std::log(side > 0 ? high : low);
    for (int k = 0; k < 12; ++k) {
      double x1 = x0 + side * step;
      if (side < 0 && x1 < 0) break;  // below one triangle
      double d0 = d(x0), d1 = d(x1);
      if (std::isnan(d0) || std::isnan(d1)) break;
      if ((d0 < 0) != (d1 < 0)) {
        for (int it = 0; it < 60; ++it) {
          double mid = 0.5 * (x0 + x1);
          ((d(mid) < 0) == (d0 < 0) ? x0 : x1) = mid;
        }
        return std::exp(0.5 * (x0 + x1));
      }
      x0 = x1;
    }
  }
  return std::nullopt;
}

}  // namespace rvr::study
