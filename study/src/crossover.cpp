// Comparisons of two renderers along an axis (see crossover.h).
#include "rvr/study/crossover.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <memory>
#include <numeric>
#include <type_traits>  // IWYU pragma: keep (std::move's type; asked for in some builds only)
#include <utility>

#include "rvr/study/cost_model.h"
#include "rvr/study/trend.h"

namespace rvr::study {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The value of the swept axis at a point: its pixel count on the "pixels" axis, else its N.
double axis_value(const Measurement& m, const std::string& axis) {
  return axis == kPixelsAxis ? m.pixels : m.n;
}

// a's and b's points at the axis values both have and with a session in common, paired, in
// increasing axis value.
struct Matched {
  std::vector<double> at, log_at;
  std::vector<PairedRatios> ratios;
  std::vector<double> d;  // each pair's log ratio estimate
};

Matched matched(const std::vector<Measurement>& a, const std::vector<Measurement>& b,
                const std::string& axis) {
  std::vector<std::pair<double, PairedRatios>> found;
  for (const Measurement& p : a)
    for (const Measurement& q : b)
      if (p.n == q.n && p.pixels == q.pixels) {
        PairedRatios r = paired_ratios(p, q);
        if (!r.runs.empty()) found.push_back({axis_value(p, axis), std::move(r)});
      }
  std::sort(found.begin(), found.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  Matched m;
  for (auto& [at, r] : found) {
    if (!m.at.empty() && at == m.at.back()) continue;  // one point per axis value
    m.at.push_back(at);
    m.log_at.push_back(std::log(at));
    m.d.push_back(ratio_estimate(r));
    m.ratios.push_back(std::move(r));
  }
  return m;
}

// The bootstrap of the points and their trend: per replicate, every point's log ratio redrawn
// hierarchically (runs, then rounds) plus the noise between points (normal, sd
// `point_noise`), and the trend of those. raw[r][j], trend[r][j]: replicate r at point j.
struct Replicates {
  std::vector<std::vector<double>> raw, trend;
};

Replicates trend_replicates(const Matched& m, const Trend& trend, double point_noise, Rng& rng,
                            int count) {
  Replicates out;
  out.raw.reserve(size_t(count));
  out.trend.reserve(size_t(count));
  std::vector<double> y(m.d.size());
  for (int r = 0; r < count; ++r) {
    for (size_t i = 0; i < y.size(); ++i)
      y[i] = resample_ratio(m.ratios[i], rng) + point_noise * rng.normal();
    out.raw.push_back(y);
    out.trend.push_back(trend.apply(y));
  }
  return out;
}

// The variance of each point's log ratio over hierarchical resamples of its own runs.
std::vector<double> run_variances(const Matched& m, Rng& rng, int count) {
  std::vector<double> out;
  std::vector<double> draws(static_cast<size_t>(count));
  for (const PairedRatios& p : m.ratios) {
    for (double& d : draws) d = resample_ratio(p, rng);
    out.push_back(variance(draws));
  }
  return out;
}

// Point j's values over the replicates.
std::vector<double> column(const std::vector<std::vector<double>>& replicates, size_t j) {
  std::vector<double> out;
  out.reserve(replicates.size());
  for (const std::vector<double>& r : replicates) out.push_back(r[j]);
  return out;
}

// For each point: the p-value that its trend is within ±delta of 0 (two one-sided t tests,
// doubled), and the side it lies on; Holm-adjusted over the points.
void judge_points(const std::vector<double>& trend, const std::vector<double>& sd, double delta,
                  double dof, std::vector<PointComparison>& points) {
  boost::math::students_t t(dof);
  std::vector<double> p(trend.size(), 1.0);
  std::vector<int> side(trend.size(), 0);
  for (size_t j = 0; j < trend.size(); ++j) {
    if (!(sd[j] > 0)) {  // no spread at all: beyond the threshold or not, exactly
      p[j] = std::fabs(trend[j]) > delta ? 0.0 : 1.0;
    } else {
      const double below =
          boost::math::cdf(boost::math::complement(t, (-delta - trend[j]) / sd[j]));
      const double above = boost::math::cdf(boost::math::complement(t, (trend[j] - delta) / sd[j]));
      p[j] = std::min(1.0, 2 * std::min(below, above));
    }
    side[j] = trend[j] < 0 ? -1 : +1;
  }
  std::vector<double> adjusted = holm_adjusted(p);
  for (size_t j = 0; j < points.size(); ++j) {
    points[j].p = adjusted[j];
    points[j].faster = adjusted[j] <= kFamilyAlpha ? side[j] : 0;
  }
}

// A maximal run of significant points of one side, in the order of the significant points
// alone (points within the noise between them do not break it).
struct Stretch {
  int side = 0;
  size_t first = 0, last = 0;  // point indices
  size_t count = 0;
  bool two_in_a_row = false;  // two of its points are neighbours in the sweep
};

std::vector<Stretch> stretches(const std::vector<PointComparison>& points) {
  std::vector<Stretch> out;
  for (size_t j = 0; j < points.size(); ++j) {
    if (points[j].faster == 0) continue;
    if (out.empty() || out.back().side != points[j].faster) {
      out.push_back({points[j].faster, j, j, 1, false});
      continue;
    }
    Stretch& s = out.back();
    s.two_in_a_row = s.two_in_a_row || s.last + 1 == j;
    s.last = j;
    ++s.count;
  }
  std::erase_if(out, [](const Stretch& s) { return !s.two_in_a_row; });
  // Stretches of one side left next to each other once the others are gone are one.
  std::vector<Stretch> merged;
  for (const Stretch& s : out) {
    if (!merged.empty() && merged.back().side == s.side) {
      merged.back().last = s.last;
      merged.back().count += s.count;
    } else {
      merged.push_back(s);
    }
  }
  return merged;
}

// Where the measured log ratios `d` cross zero between a stretch of side `from` ending at point
// `last` and one of the other side starting at point `first`: the bracket widened outward to
// the nearest points that are on those sides in `d` itself, the crossing interpolated in log of
// the axis (the middle of the first and last when the points between change sign more than
// once). NaN when `d` has no point of side `from` at or below `last` (the crossing lies below
// the range in it), or none of the other side at or above `first` (above the range).
double crossing_in(const std::vector<double>& log_at, const std::vector<double>& d, size_t last,
                   size_t first, int from) {
  auto on = [&](size_t i, int side) { return side < 0 ? d[i] < 0 : d[i] > 0; };
  size_t lo = last, hi = first;
  while (!on(lo, from))
    if (lo-- == 0) return -kInf;
  while (!on(hi, -from))
    if (++hi == d.size()) return kInf;
  return zero_crossing(log_at, d, lo, hi);
}

// The replicates' positions of the crossing between points `last` and `first`: in each, the
// crossing of its own log ratios by the same rule; ±inf where it has none in the range.
std::vector<double> replicate_positions(const std::vector<std::vector<double>>& replicates,
                                        const std::vector<double>& log_at, size_t last,
                                        size_t first, int from) {
  std::vector<double> positions;
  positions.reserve(replicates.size());
  for (const std::vector<double>& d : replicates) {
    const double x = crossing_in(log_at, d, last, first, from);
    // No point of side `from` at or below: the crossing lies below the range; no point of the
    // other side above: above it.
    positions.push_back(std::isinf(x) ? x : std::exp(x));
  }
  return positions;
}

// The trend's ratio of the slower over the faster at point j.
double lead(const PointComparison& p) {
  return p.faster < 0 ? 1.0 / p.trend : p.trend;
}

Dominance dominance_of(const Comparison& c, int side) {
  Dominance d;
  d.faster = side < 0 ? c.a : c.b;
  d.slower = side < 0 ? c.b : c.a;
  d.scene = c.scene;
  d.axis = c.axis;
  d.pixels = c.pixels;
  d.n = c.n;
  d.range_low = c.points.front().at;
  d.range_high = c.points.back().at;
  d.points = c.points.size();
  d.min_ratio = kInf;
  d.significant_low = kInf;
  d.significant_high = 0;
  for (const PointComparison& p : c.points) {
    if (p.faster == side) {
      ++d.significant;
      d.significant_low = std::min(d.significant_low, p.at);
      d.significant_high = std::max(d.significant_high, p.at);
      if (lead(p) < d.min_ratio) d.min_ratio = lead(p), d.at = p.at;
    }
    const double slower_over_faster = side < 0 ? 1.0 / p.ratio : p.ratio;
    if (slower_over_faster < 1) {
      d.contrary.push_back(p.at);
      d.contrary_ratios.push_back(1.0 / slower_over_faster);
    }
  }
  return d;
}

}  // namespace

std::vector<double> holm_adjusted(const std::vector<double>& p) {
  std::vector<size_t> order(p.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t i, size_t j) { return p[i] < p[j]; });
  std::vector<double> out(p.size());
  double running = 0;
  for (size_t k = 0; k < order.size(); ++k) {
    running = std::max(running, std::min(1.0, double(order.size() - k) * p[order[k]]));
    out[order[k]] = running;
  }
  return out;
}

CurveComparison compare_curves(const std::vector<Measurement>& a, const std::vector<Measurement>& b,
                               const std::string& axis, const CompareOptions& options) {
  CurveComparison out;
  Comparison& c = out.comparison;
  if (a.empty() || b.empty()) return out;
  const bool pixels_axis = axis == kPixelsAxis;
  c.a = a[0].renderer;
  c.b = b[0].renderer;
  c.scene = a[0].scene;
  c.axis = axis;
  c.pixels = pixels_axis ? 0 : a[0].pixels;
  c.n = pixels_axis ? a[0].n : 0;
  const Matched m = matched(a, b, axis);
  for (size_t i = 0; i < m.at.size(); ++i)
    c.points.push_back({m.at[i], std::exp(m.d[i]), kNaN, {kNaN, kNaN}, 1.0, 0});
  if (m.at.size() < kMinComparedPoints) {
    c.inconclusive = fmt::format(
        "only {} points measured by both: at least {} are needed to tell a trend from the noise "
        "between points",
        m.at.size(), kMinComparedPoints);
    return out;
  }
  const Trend trend(m.log_at);
  Rng rng(options.boot.seed);
  const int count = std::max(options.boot.replicates, 100);
  const std::vector<double> v = run_variances(m, rng, count);
  const double mean_v = std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
  c.point_noise = std::sqrt(std::max(0.0, trend.residual_variance(m.d) - mean_v));
  c.dof = trend.residual_dof();
  const std::vector<double> t = trend.apply(m.d);
  const Replicates replicates = trend_replicates(m, trend, c.point_noise, rng, count);
  std::vector<double> sd;
  for (size_t j = 0; j < t.size(); ++j) {
    std::vector<double> col = column(replicates.trend, j);
    sd.push_back(std::sqrt(variance(col)));
    Interval ci = percentile_interval(col);
    c.points[j].trend = std::exp(t[j]);
    c.points[j].ci95 = {std::exp(ci.low), std::exp(ci.high)};
  }
  judge_points(t, sd, std::log1p(options.noise_threshold), c.dof, c.points);
  const std::vector<Stretch> found = stretches(c.points);
  for (size_t k = 0; k + 1 < found.size(); ++k) {
    const Stretch &lo = found[k], &hi = found[k + 1];
    Crossover x;
    x.a = c.a;
    x.b = c.b;
    x.scene = c.scene;
    x.axis = axis;
    // Placed where the measured ratios cross between the two stretches (where the trend does,
    // in the rare case that the measured ratios are on neither side there).
    double log_x = crossing_in(m.log_at, m.d, lo.last, hi.first, lo.side);
    if (!std::isfinite(log_x)) log_x = zero_crossing(m.log_at, t, lo.last, hi.first);
    x.value = std::exp(log_x);
    x.ci95 = percentile_interval(
        replicate_positions(replicates.raw, m.log_at, lo.last, hi.first, lo.side));
    x.pixels = c.pixels;
    x.n = c.n;
    x.a_faster_below = lo.side < 0;
    x.range_low = m.at.front();
    x.range_high = m.at.back();
    x.below_points = lo.count;
    x.above_points = hi.count;
    x.below_ratio = lead(c.points[lo.last]);
    x.above_ratio = lead(c.points[hi.first]);
    out.crossovers.push_back(x);
  }
  if (!out.crossovers.empty()) return out;
  size_t faster_a = 0, faster_b = 0;
  for (const PointComparison& p : c.points) (p.faster < 0 ? faster_a : faster_b) += p.faster != 0;
  if (faster_a + faster_b == 0) {
    out.tie = true;
    return out;
  }
  out.dominance = dominance_of(c, faster_a >= faster_b ? -1 : +1);
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
