// Crossovers of measured curves and their bootstrap intervals (see crossover.h).
#include "rvr/study/crossover.h"

#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <memory>
#include <utility>

#include "rvr/shared/check.h"
#include "rvr/study/cost_model.h"

namespace rvr::study {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The value of the swept axis at a point: its pixel count on the "pixels" axis, else its N.
double axis_value(const Measurement& m, const std::string& axis) {
  return axis == kPixelsAxis ? m.pixels : m.n;
}

// a's and b's points at the axis values both have, in increasing axis value.
void matched(const std::vector<Measurement>& a, const std::vector<Measurement>& b,
             const std::string& axis, std::vector<Measurement>& ma, std::vector<Measurement>& mb) {
  for (const Measurement& p : a)
    for (const Measurement& q : b)
      if (p.n == q.n && p.pixels == q.pixels) {
        ma.push_back(p);
        mb.push_back(q);
      }
  std::vector<size_t> idx(ma.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(),
            [&](size_t i, size_t j) { return axis_value(ma[i], axis) < axis_value(ma[j], axis); });
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
  RVR_CHECK(log_n.size() == d.size(), "one ratio per point: ", d.size(), " ratios at ",
            log_n.size(), " points");
  std::vector<Crossing> out;
  for (size_t i = 0; i + 1 < d.size(); ++i) {
    if ((d[i] < 0) == (d[i + 1] < 0) || d[i] == 0) continue;
    double f = d[i] / (d[i] - d[i + 1]);
    out.push_back({log_n[i] + f * (log_n[i + 1] - log_n[i]), d[i] < 0});
  }
  return out;
}

std::vector<double> log_ratios(const std::vector<double>& ta, const std::vector<double>& tb) {
  RVR_CHECK(ta.size() == tb.size(), "both renderers timed at the same points: ", ta.size(), " and ",
            tb.size());
  std::vector<double> d;
  for (size_t i = 0; i < ta.size(); ++i) d.push_back(std::log(ta[i] / tb[i]));
  return d;
}

// Each replicate's log ratios d = log(t_a / t_b) at the matched points.
std::vector<std::vector<double>> replicate_ratios(const std::vector<Measurement>& a,
                                                  const std::vector<Measurement>& b,
                                                  const BootstrapOptions& boot) {
  Rng rng(boot.seed);
  std::vector<std::vector<double>> out;
  for (int r = 0; r < boot.replicates; ++r) {
    std::vector<double> ta = resample_medians(a, rng), tb = resample_medians(b, rng);
    out.push_back(log_ratios(ta, tb));
  }
  return out;
}

// Which renderer each point shows faster beyond its timing noise: −1 (a), +1 (b), or 0 when the
// 95% interval of d over the replicates holds 0 (a tie).
std::vector<int> significant_signs(const std::vector<std::vector<double>>& replicates,
                                   size_t points) {
  std::vector<int> signs(points, 0);
  for (const auto& d : replicates)
    RVR_DCHECK(d.size() == points, "a replicate holds one ratio per point: ", d.size(), " of ",
               points);
  for (size_t i = 0; i < points; ++i) {
    std::vector<double> di;
    di.reserve(replicates.size());
    for (const auto& d : replicates) di.push_back(d[i]);
    Interval ci = percentile_interval(di);
    signs[i] = ci.high < 0 ? -1 : (ci.low > 0 ? +1 : 0);
  }
  return signs;
}

// The crossings of the measured curves that the noise cannot explain: one for every pair of
// consecutive significant points of opposite signs, placed at the measured sign change between
// them (the geometric middle of the first and last when ties between them change sign more
// than once).
std::vector<Crossing> significant_crossings(const std::vector<double>& log_n,
                                            const std::vector<double>& d,
                                            const std::vector<int>& signs) {
  RVR_CHECK(signs.size() == d.size() && log_n.size() == d.size(),
            "one sign and one position per ratio: ", signs.size(), ", ", log_n.size(), ", ",
            d.size());
  std::vector<Crossing> out;
  size_t last = signs.size();  // the previous significant point
  for (size_t j = 0; j < signs.size(); ++j) {
    if (signs[j] == 0) continue;
    if (last != signs.size() && signs[j] != signs[last]) {
      std::vector<double> sub_n(log_n.begin() + long(last), log_n.begin() + long(j) + 1);
      std::vector<double> sub_d(d.begin() + long(last), d.begin() + long(j) + 1);
      std::vector<Crossing> raw = crossings(sub_n, sub_d);
      double x = raw.empty() ? 0.5 * (log_n[last] + log_n[j])
                             : 0.5 * (raw.front().log_n + raw.back().log_n);
      out.push_back({x, signs[last] < 0});
    }
    last = j;
  }
  return out;
}

// The replicates' positions of the crossing `c`: the nearest of each replicate's crossings of
// the same direction, or ±inf when a replicate has none (one renderer faster everywhere).
std::vector<double> replicate_positions(const std::vector<std::vector<double>>& replicates,
                                        const std::vector<double>& log_n, const Crossing& c) {
  std::vector<double> positions;
  for (const std::vector<double>& d : replicates) {
    RVR_DCHECK(!d.empty() && d.size() == log_n.size(),
               "a replicate's ratios at every point: ", d.size(), " of ", log_n.size());
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

// The renderer faster wherever the difference is beyond the noise, and its smallest lead
// there; nullopt when no point is.
std::optional<Dominance> dominance(const std::vector<Measurement>& a,
                                   const std::vector<Measurement>& b, const std::vector<double>& d,
                                   const std::vector<int>& signs, const std::string& axis) {
  size_t first = 0;
  while (first < signs.size() && signs[first] == 0) ++first;
  if (first == signs.size()) return std::nullopt;
  Dominance dom;
  bool a_faster = signs[first] < 0;
  dom.faster = a_faster ? a[0].renderer : b[0].renderer;
  dom.slower = a_faster ? b[0].renderer : a[0].renderer;
  dom.min_ratio = kInf;
  for (size_t i = 0; i < d.size(); ++i)
    if (signs[i] != 0 && std::exp(std::fabs(d[i])) < dom.min_ratio) {
      dom.min_ratio = std::exp(std::fabs(d[i]));
      dom.at = axis_value(a[i], axis);
    }
  return dom;
}

}  // namespace

CurveComparison compare_curves(const std::vector<Measurement>& a_in,
                               const std::vector<Measurement>& b_in, const std::string& axis,
                               const BootstrapOptions& boot) {
  CurveComparison out;
  std::vector<Measurement> a, b;
  matched(a_in, b_in, axis, a, b);
  if (a.empty()) return out;
  const bool pixels_axis = axis == kPixelsAxis;
  const double low = axis_value(a.front(), axis), high = axis_value(a.back(), axis);
  std::vector<double> log_n, ta, tb;
  for (size_t i = 0; i < a.size(); ++i) {
    log_n.push_back(std::log(axis_value(a[i], axis)));
    ta.push_back(typical_seconds(a[i]));
    tb.push_back(typical_seconds(b[i]));
  }
  std::vector<double> d = log_ratios(ta, tb);
  std::vector<std::vector<double>> replicates = replicate_ratios(a, b, boot);
  std::vector<int> signs = significant_signs(replicates, a.size());
  for (const Crossing& c : significant_crossings(log_n, d, signs)) {
    Crossover x;
    x.a = a[0].renderer;
    x.b = b[0].renderer;
    x.scene = a[0].scene;
    x.axis = axis;
    x.value = std::exp(c.log_n);
    x.ci95 = percentile_interval(replicate_positions(replicates, log_n, c));
    x.pixels = pixels_axis ? 0 : a[0].pixels;
    x.n = pixels_axis ? a[0].n : 0;
    x.a_faster_below = c.a_faster_below;
    x.range_low = low;
    x.range_high = high;
    out.crossovers.push_back(x);
  }
  if (out.crossovers.empty()) {
    std::optional<Dominance> found = dominance(a, b, d, signs, axis);
    if (!found) {
      out.tie = true;
      return out;
    }
    Dominance dom = *found;
    dom.scene = a[0].scene;
    dom.axis = axis;
    dom.pixels = pixels_axis ? 0 : a[0].pixels;
    dom.n = pixels_axis ? a[0].n : 0;
    dom.range_low = low;
    dom.range_high = high;
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
    double ta = predict(fa.model, ca, pixels, n), tb = predict(fb.model, cb, pixels, n);
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
