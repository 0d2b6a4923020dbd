// Log-log charts of study.html (see loglog_chart.h).
#include "loglog_chart.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "rvr/present/chart_axes.h"
#include "rvr/present/html_escape.h"
#include "rvr/present/svg.h"

namespace rvr::study {
namespace {

using present::escape_html;

// The drawing's size in SVG units (it scales with the page) and the plot area's margins.
constexpr double kWidth = 900, kHeight = 400;
constexpr double kLeft = 78, kRight = 20, kTop = 14, kBottom = 50;
constexpr int kCurveSamples = 160;
// How far beyond the measured times the models may widen the time axis, as a factor.
constexpr double kModelHeadroom = 10;

bool positive(double v) {
  return std::isfinite(v) && v > 0;
}

// A range of log10 values.
struct LogRange {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!positive(v)) return;
    lo = std::min(lo, std::log10(v));
    hi = std::max(hi, std::log10(v));
  }
  bool empty() const { return lo > hi; }
  // Widened to whole decades, at least one.
  LogRange decades() const {
    LogRange d;
    d.lo = empty() ? 0 : std::floor(lo + 1e-9);
    d.hi = empty() ? 1 : std::ceil(hi - 1e-9);
    if (d.hi <= d.lo) d.hi = d.lo + 1;
    return d;
  }
};

// Data to SVG coordinates: the plot area and the two logarithmic scales.
class Frame {
 public:
  Frame(const LogRange& x, const LogRange& y)
      : x_(present::Scale::log10(x.lo, x.hi, kArea.left, kArea.right)),
        y_(present::Scale::log10(y.lo, y.hi, kArea.bottom, kArea.top)),
        x_range_(x),
        y_range_(y) {}
  static const present::PlotArea& area() { return kArea; }
  double px(double x) const { return x_(x); }
  double py(double t) const { return y_(t); }
  // px clamped to the plot; ±inf at the edges, NaN at `nan_side`'s edge.
  double px_edge(double x, double nan_side) const {
    if (std::isnan(x)) return nan_side;
    if (x == std::numeric_limits<double>::infinity()) return kArea.right;
    if (x <= 0) return kArea.left;
    return std::clamp(px(x), kArea.left, kArea.right);
  }
  const present::Scale& x_scale() const { return x_; }
  const present::Scale& y_scale() const { return y_; }
  const LogRange& x() const { return x_range_; }
  const LogRange& y() const { return y_range_; }

 private:
  static constexpr present::PlotArea kArea{kLeft, kTop, kWidth - kRight, kHeight - kBottom};
  present::Scale x_, y_;
  LogRange x_range_, y_range_;
};

// The x axis covers every point and every crossing (an extrapolated one too) in whole decades.
LogRange x_range(const ChartSpec& spec) {
  LogRange r;
  for (const ChartSeries& s : spec.series)
    for (const ChartPoint& p : s.points) r.add(p.x);
  for (const ChartCrossing& c : spec.crossings) {
    r.add(c.value);
    r.add(c.low);
    r.add(c.high);
  }
  return r.decades();
}

// The time axis covers every repetition, and the models over the x axis within a headroom.
LogRange y_range(const ChartSpec& spec, const LogRange& x) {
  LogRange r;
  for (const ChartSeries& s : spec.series)
    for (const ChartPoint& p : s.points) {
      r.add(p.low);
      r.add(p.high);
    }
  if (r.empty()) return r.decades();
  LogRange models = r;
  for (const ChartSeries& s : spec.series) {
    if (!s.model) continue;
    for (int i = 0; i <= 16; ++i)
      models.add(s.model(std::pow(10.0, x.lo + (x.hi - x.lo) * i / 16)));
  }
  const double head = std::log10(kModelHeadroom);
  r.lo = std::max(models.lo, r.lo - head);
  r.hi = std::min(models.hi, r.hi + head);
  return r.decades();
}

// The decades ticked and labelled on both axes, and the axes' names.
std::string axes_svg(const Frame& f, const ChartSpec& spec) {
  const present::PlotArea& area = Frame::area();
  return present::x_ticks(f.x_scale(), area, present::decade_ticks(int(f.x().lo), int(f.x().hi))) +
         present::y_ticks(f.y_scale(), area, present::decade_ticks(int(f.y().lo), int(f.y().hi))) +
         present::axis_names(area, kHeight - 8, spec.x_label, spec.y_label);
}

// The spacing of renderers' marks at one x (points_svg's dodge), and a mark's radius.
constexpr double kDodge = 4.0;
constexpr double kMarkRadius = 3.5;

// Grey over the parts of the x axis outside the swept range, short of the outermost marks
// (shifted sideways by their dodge) so that no measured point lies under it.
std::string unmeasured_svg(const Frame& f, const ChartSpec& spec) {
  const present::PlotArea& area = Frame::area();
  const double clearance = kDodge * std::max(0.0, double(spec.series.size()) - 1) / 2 + kMarkRadius;
  std::string o;
  auto shade = [&](double x0, double x1) {
    if (x1 - x0 < 1) return;
    o += present::rect({{"class", "unmeasured"}}, x0, area.top, x1 - x0, area.height());
    if (x1 - x0 > 80)
      o += present::text({{"class", "unmeasured-label"}, {"text-anchor", "middle"}}, (x0 + x1) / 2,
                         area.bottom - 8, "not measured");
  };
  if (positive(spec.swept_low)) shade(area.left, f.px_edge(spec.swept_low, area.left) - clearance);
  if (positive(spec.swept_high))
    shade(f.px_edge(spec.swept_high, area.right) + clearance, area.right);
  return o;
}

// A crossing: its interval shaded (to the edge for an open end) at `opacity`, its line and its
// tag, the tags of successive crossings on successive rows.
std::string crossing_svg(const Frame& f, const ChartCrossing& c, int index, double opacity) {
  const present::PlotArea& area = Frame::area();
  std::string o;
  if (c.measured || std::isfinite(c.low) || std::isfinite(c.high)) {
    double x0 = f.px_edge(c.low, area.left), x1 = f.px_edge(c.high, area.right);
    if (x1 < x0) std::swap(x0, x1);
    o +=
        present::rect({{"class", "ci-band"},
                       {"fill-opacity", fmt::format("{:.3f}", c.measured ? opacity : opacity / 2)}},
                      x0, area.top, std::max(1.0, x1 - x0), area.height());
  }
  const double x = f.px_edge(c.value, area.left);
  o += present::line({{"class", "crossover-line"}}, x, area.top, x, area.bottom);
  const double y = area.top + 12 + 18 * (index % 3);
  o += present::circle({{"class", "crossover-tag"}}, x, y, 8) +
       present::text({{"class", "crossover-label"}, {"text-anchor", "middle"}}, x, y + 4,
                     escape_html(c.tag)) +
       present::tooltip(c.label);
  return present::element("g",
                          {{"class", c.measured ? "crossover measured" : "crossover extrapolated"},
                           {"data-measured", c.measured ? "true" : "false"}},
                          o);
}

// The model's curve over the whole x axis, broken where it is not a positive time; dashed and
// labelled when the model does not fit, the label `row` lines above the curve's end. A model
// with no positive time on the axis is a label in the chart's corner, `row` lines down.
std::string curve_svg(const Frame& f, const ChartSeries& s, int row) {
  const present::PlotArea& area = Frame::area();
  std::vector<std::vector<present::Point>> pieces(1);
  double label_x = -1, label_y = 0;
  const LogRange& r = f.x();
  for (int i = 0; i <= kCurveSamples; ++i) {
    const double x = std::pow(10.0, r.lo + (r.hi - r.lo) * i / kCurveSamples);
    const double t = s.model(x);
    if (!positive(t)) {
      if (!pieces.back().empty()) pieces.emplace_back();
      continue;
    }
    // Far outside the plot the clip hides it; clamped so the numbers stay small.
    const double y = std::clamp(f.py(t), area.top - kHeight, area.bottom + kHeight);
    pieces.back().push_back({f.px(x), y});
    if (y >= area.top + 10 && y <= area.bottom) label_x = f.px(x), label_y = y;
  }
  if (pieces.front().empty())  // no positive time anywhere on the axis: said, not left out
    return present::text({{"class", "model-label model-not-positive"}, {"fill", s.colour}},
                         area.left + 8, area.top + 14 + 15 * row,
                         escape_html(s.name) + ": model not positive over this range" +
                             (s.fits ? "" : " (does not fit)"));
  present::Attributes look = {{"class", s.fits ? "model fits" : "model no-fit"},
                              {"data-renderer", s.name},
                              {"stroke", s.colour}};
  if (!s.fits) look.emplace_back("stroke-dasharray", "7 5");
  std::string o = present::path(
      look, pieces, present::tooltip(s.name + " model" + (s.fits ? "" : ": does not fit")));
  const double label_above = label_y - 7 - 15 * row;  // below the curve when that is off the top
  if (!s.fits && label_x >= 0)
    o += present::text({{"class", "model-label"}, {"text-anchor", "end"}, {"fill", s.colour}},
                       label_x, label_above < area.top + 12 ? label_y + 16 + 15 * row : label_above,
                       escape_html(s.name) + ": does not fit");
  return o;
}

// The measured points: a line from the fastest to the slowest repetition and a mark at the
// typical time, shifted by `dodge` units so that renderers at the same x stay apart.
std::string points_svg(const Frame& f, const ChartSeries& s, double dodge) {
  std::string o;
  for (const ChartPoint& p : s.points) {
    if (!positive(p.x) || !positive(p.typical)) continue;
    const double x = f.px(p.x) + dodge;
    const double lo = positive(p.low) ? f.py(p.low) : f.py(p.typical);
    const double hi = positive(p.high) ? f.py(p.high) : f.py(p.typical);
    o += present::element(
        "g", {{"class", "point"}},
        present::tooltip(p.tooltip) +
            present::line({{"class", "spread"}, {"stroke", s.colour}}, x, hi, x, lo) +
            present::circle({{"class", "mark"},
                             {"fill", s.colour},
                             {"data-x", fmt::format("{}", p.x)},
                             {"data-t", fmt::format("{}", p.typical)}},
                            x, f.py(p.typical), kMarkRadius));
  }
  return o;
}

}  // namespace

std::string loglog_chart_svg(const ChartSpec& spec) {
  const LogRange x = x_range(spec);
  const Frame f(x, y_range(spec, x));
  const present::PlotArea& area = Frame::area();
  const std::string clip = spec.id + "-clip";
  std::string o = present::chart_open({spec.id, "study-chart", kWidth, kHeight, spec.title, ""});
  o += "<defs>" +
       present::element("clipPath", {{"id", clip}},
                        present::rect({}, area.left, area.top, area.width(), area.height())) +
       "</defs>";
  o += present::plot_frame(area) + unmeasured_svg(f, spec) + axes_svg(f, spec);
  std::string plotted;
  // Overlapping bands add up: the more there are, the fainter each.
  const double band_opacity =
      std::min(0.15, 0.6 / double(std::max<size_t>(1, spec.crossings.size())));
  for (size_t i = 0; i < spec.crossings.size(); ++i)
    plotted += crossing_svg(f, spec.crossings[i], int(i), band_opacity);
  const double n = double(spec.series.size());
  int unfit = 0;  // models that do not fit so far: their labels go on successive rows
  for (size_t i = 0; i < spec.series.size(); ++i) {
    const ChartSeries& s = spec.series[i];
    plotted += "<g class=\"series\" data-renderer=\"" + escape_html(s.name) + "\">";
    if (s.model) plotted += curve_svg(f, s, s.fits ? 0 : unfit++);
    plotted += points_svg(f, s, kDodge * (double(i) - (n - 1) / 2)) + "</g>";
  }
  o += present::element("g", {{"class", "plotted"}, {"clip-path", "url(#" + clip + ")"}}, plotted);
  return o + "</svg>";
}

}  // namespace rvr::study
