// Log-log charts of study.html (see loglog_chart.h).
#include "loglog_chart.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "html_text.h"
#include "rvr/core/html_escape.h"

namespace rvr::study {
namespace {

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

// Data to SVG coordinates.
class Frame {
 public:
  Frame(LogRange x, LogRange y) : x_(x), y_(y) {}
  static double left() { return kLeft; }
  static double right() { return kWidth - kRight; }
  static double top() { return kTop; }
  static double bottom() { return kHeight - kBottom; }
  double px(double x) const { return left() + (std::log10(x) - x_.lo) / span(x_) * width(); }
  double py(double t) const { return bottom() - (std::log10(t) - y_.lo) / span(y_) * height(); }
  // px clamped to the plot; ±inf at the edges, NaN at `nan_side`'s edge.
  double px_edge(double x, double nan_side) const {
    if (std::isnan(x)) return nan_side;
    if (x == std::numeric_limits<double>::infinity()) return right();
    if (x <= 0) return left();
    return std::clamp(px(x), left(), right());
  }
  const LogRange& x() const { return x_; }
  const LogRange& y() const { return y_; }

 private:
  static double span(const LogRange& r) { return r.hi - r.lo; }
  static double width() { return right() - left(); }
  static double height() { return bottom() - top(); }
  LogRange x_, y_;
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

// Every how many decades a tick is labelled, for at most 8 labels.
int label_step(const LogRange& r) {
  return std::max(1, int(std::ceil((r.hi - r.lo) / 8)));
}

// Grid lines and labels at the decades of the x axis (minor lines at 2..9 when few decades).
std::string x_ticks_svg(const Frame& f) {
  std::string o;
  const LogRange& r = f.x();
  const int step = label_step(r);
  for (int k = int(r.lo); k <= int(r.hi); ++k) {
    double x = f.px(std::pow(10.0, k));
    o += fmt::format("<line class=\"grid\" x1=\"{0:.1f}\" x2=\"{0:.1f}\" y1=\"{1}\" y2=\"{2}\"/>",
                     x, Frame::top(), Frame::bottom());
    if ((k - int(r.lo)) % step == 0)
      o +=
          fmt::format("<text class=\"tick\" x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\">{}</text>",
                      x, Frame::bottom() + 18, decade_svg(k));
    for (int m = 2; m <= 9 && k < int(r.hi) && r.hi - r.lo <= 5; ++m)
      o +=
          fmt::format("<line class=\"minor\" x1=\"{0:.1f}\" x2=\"{0:.1f}\" y1=\"{1}\" y2=\"{2}\"/>",
                      f.px(m * std::pow(10.0, k)), Frame::top(), Frame::bottom());
  }
  return o;
}

// The same for the time axis.
std::string y_ticks_svg(const Frame& f) {
  std::string o;
  const LogRange& r = f.y();
  const int step = label_step(r);
  for (int k = int(r.lo); k <= int(r.hi); ++k) {
    double y = f.py(std::pow(10.0, k));
    o += fmt::format("<line class=\"grid\" x1=\"{0}\" x2=\"{1}\" y1=\"{2:.1f}\" y2=\"{2:.1f}\"/>",
                     Frame::left(), Frame::right(), y);
    if ((k - int(r.lo)) % step == 0)
      o += fmt::format("<text class=\"tick\" x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>",
                       Frame::left() - 8, y + 4, decade_svg(k));
    for (int m = 2; m <= 9 && k < int(r.hi) && r.hi - r.lo <= 5; ++m)
      o +=
          fmt::format("<line class=\"minor\" x1=\"{0}\" x2=\"{1}\" y1=\"{2:.1f}\" y2=\"{2:.1f}\"/>",
                      Frame::left(), Frame::right(), f.py(m * std::pow(10.0, k)));
  }
  return o;
}

// The plot's frame and the axes' names.
std::string axes_svg(const ChartSpec& spec) {
  return fmt::format(
      "<rect class=\"plot\" x=\"{0}\" y=\"{1}\" width=\"{2}\" height=\"{3}\"/>"
      "<text class=\"axis-label\" x=\"{4}\" y=\"{5}\" text-anchor=\"middle\">{6}</text>"
      "<text class=\"axis-label\" transform=\"translate(16 {7}) rotate(-90)\" "
      "text-anchor=\"middle\">{8}</text>",
      Frame::left(), Frame::top(), Frame::right() - Frame::left(), Frame::bottom() - Frame::top(),
      (Frame::left() + Frame::right()) / 2, kHeight - 8, escape_html(spec.x_label),
      (Frame::top() + Frame::bottom()) / 2, escape_html(spec.y_label));
}

// The spacing of renderers' marks at one x (points_svg's dodge), and a mark's radius.
constexpr double kDodge = 4.0;
constexpr double kMarkRadius = 3.5;

// Grey over the parts of the x axis outside the swept range, short of the outermost marks
// (shifted sideways by their dodge) so that no measured point lies under it.
std::string unmeasured_svg(const Frame& f, const ChartSpec& spec) {
  const double clearance = kDodge * std::max(0.0, double(spec.series.size()) - 1) / 2 + kMarkRadius;
  std::string o;
  auto shade = [&](double x0, double x1) {
    if (x1 - x0 < 1) return;
    o += fmt::format(
        "<rect class=\"unmeasured\" x=\"{:.1f}\" y=\"{}\" width=\"{:.1f}\" height=\"{}\"/>", x0,
        Frame::top(), x1 - x0, Frame::bottom() - Frame::top());
    if (x1 - x0 > 80)
      o += fmt::format(
          "<text class=\"unmeasured-label\" x=\"{:.1f}\" y=\"{}\" "
          "text-anchor=\"middle\">not measured</text>",
          (x0 + x1) / 2, Frame::bottom() - 8);
  };
  if (positive(spec.swept_low))
    shade(Frame::left(), f.px_edge(spec.swept_low, Frame::left()) - clearance);
  if (positive(spec.swept_high))
    shade(f.px_edge(spec.swept_high, Frame::right()) + clearance, Frame::right());
  return o;
}

// A crossing: its interval shaded (to the edge for an open end) at `opacity`, its line and its
// tag, the tags of successive crossings on successive rows.
std::string crossing_svg(const Frame& f, const ChartCrossing& c, int index, double opacity) {
  const char* kind = c.measured ? "measured" : "extrapolated";
  std::string o = fmt::format("<g class=\"crossover {0}\" data-measured=\"{1}\">", kind,
                              c.measured ? "true" : "false");
  if (c.measured || std::isfinite(c.low) || std::isfinite(c.high)) {
    double x0 = f.px_edge(c.low, Frame::left()), x1 = f.px_edge(c.high, Frame::right());
    if (x1 < x0) std::swap(x0, x1);
    o += fmt::format(
        "<rect class=\"ci-band\" x=\"{:.1f}\" y=\"{}\" width=\"{:.1f}\" height=\"{}\" "
        "fill-opacity=\"{:.3f}\"/>",
        x0, Frame::top(), std::max(1.0, x1 - x0), Frame::bottom() - Frame::top(),
        c.measured ? opacity : opacity / 2);
  }
  const double x = f.px_edge(c.value, Frame::left());
  o += fmt::format(
      "<line class=\"crossover-line\" x1=\"{0:.1f}\" x2=\"{0:.1f}\" y1=\"{1}\" "
      "y2=\"{2}\"/>",
      x, Frame::top(), Frame::bottom());
  const double y = Frame::top() + 12 + 18 * (index % 3);
  o += fmt::format(
      "<circle class=\"crossover-tag\" cx=\"{0:.1f}\" cy=\"{1}\" r=\"8\"/><text "
      "class=\"crossover-label\" x=\"{0:.1f}\" y=\"{2}\" text-anchor=\"middle\">{3}</text>"
      "<title>{4}</title></g>",
      x, y, y + 4, escape_html(c.tag), escape_html(c.label));
  return o;
}

// The model's curve over the whole x axis, broken where it is not a positive time; dashed and
// labelled when the model does not fit, the label `row` lines above the curve's end. A model
// with no positive time on the axis is a label in the chart's corner, `row` lines down.
std::string curve_svg(const Frame& f, const ChartSeries& s, int row) {
  std::string d;
  bool pen_down = false;
  double label_x = -1, label_y = 0;
  const LogRange& r = f.x();
  for (int i = 0; i <= kCurveSamples; ++i) {
    const double x = std::pow(10.0, r.lo + (r.hi - r.lo) * i / kCurveSamples);
    const double t = s.model(x);
    if (!positive(t)) {
      pen_down = false;
      continue;
    }
    // Far outside the plot the clip hides it; clamped so the numbers stay small.
    const double y = std::clamp(f.py(t), Frame::top() - kHeight, Frame::bottom() + kHeight);
    d += fmt::format("{}{:.1f},{:.1f}", pen_down ? " L" : " M", f.px(x), y);
    pen_down = true;
    if (y >= Frame::top() + 10 && y <= Frame::bottom()) label_x = f.px(x), label_y = y;
  }
  if (d.empty())  // no positive time anywhere on the axis: said, rather than silently absent
    return fmt::format(
        "<text class=\"model-label model-not-positive\" x=\"{:.1f}\" y=\"{:.1f}\" "
        "fill=\"{}\">{}: model not positive over this range{}</text>",
        Frame::left() + 8, Frame::top() + 14 + 15 * row, s.colour, escape_html(s.name),
        s.fits ? "" : " (does not fit)");
  std::string o = fmt::format(
      "<path class=\"model {}\" data-renderer=\"{}\" d=\"{}\" stroke=\"{}\"{}><title>{} model{}"
      "</title></path>",
      s.fits ? "fits" : "no-fit", escape_html(s.name), d.substr(1), s.colour,
      s.fits ? "" : " stroke-dasharray=\"7 5\"", escape_html(s.name),
      s.fits ? "" : ": does not fit");
  const double label_above = label_y - 7 - 15 * row;  // below the curve when that is off the top
  if (!s.fits && label_x >= 0)
    o += fmt::format(
        "<text class=\"model-label\" x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\" "
        "fill=\"{}\">{}: does not fit</text>",
        label_x, label_above < Frame::top() + 12 ? label_y + 16 + 15 * row : label_above, s.colour,
        escape_html(s.name));
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
    o += fmt::format(
        "<g class=\"point\"><title>{0}</title><line class=\"spread\" x1=\"{1:.1f}\" "
        "x2=\"{1:.1f}\" y1=\"{2:.1f}\" y2=\"{3:.1f}\" stroke=\"{4}\"/><circle class=\"mark\" "
        "cx=\"{1:.1f}\" cy=\"{5:.1f}\" r=\"{8}\" fill=\"{4}\" data-x=\"{6}\" data-t=\"{7}\"/></g>",
        escape_html(p.tooltip), x, hi, lo, s.colour, f.py(p.typical), p.x, p.typical, kMarkRadius);
  }
  return o;
}

}  // namespace

std::string loglog_chart_svg(const ChartSpec& spec) {
  const LogRange x = x_range(spec);
  const Frame f(x, y_range(spec, x));
  const std::string id = escape_html(spec.id);
  std::string o = fmt::format(
      "<svg class=\"study-chart\" id=\"{0}\" viewBox=\"0 0 {1} {2}\" role=\"img\" "
      "aria-labelledby=\"{0}-title\"><title id=\"{0}-title\">{3}</title>"
      "<defs><clipPath id=\"{0}-clip\"><rect x=\"{4}\" y=\"{5}\" width=\"{6}\" height=\"{7}\"/>"
      "</clipPath></defs>",
      id, kWidth, kHeight, escape_html(spec.title), Frame::left(), Frame::top(),
      Frame::right() - Frame::left(), Frame::bottom() - Frame::top());
  o += axes_svg(spec) + unmeasured_svg(f, spec) + x_ticks_svg(f) + y_ticks_svg(f);
  o += fmt::format("<g class=\"plotted\" clip-path=\"url(#{}-clip)\">", id);
  // Overlapping bands add up: the more there are, the fainter each.
  const double band_opacity =
      std::min(0.15, 0.6 / double(std::max<size_t>(1, spec.crossings.size())));
  for (size_t i = 0; i < spec.crossings.size(); ++i)
    o += crossing_svg(f, spec.crossings[i], int(i), band_opacity);
  const double n = double(spec.series.size());
  int unfit = 0;  // models that do not fit so far: their labels go on successive rows
  for (size_t i = 0; i < spec.series.size(); ++i) {
    const ChartSeries& s = spec.series[i];
    o += fmt::format("<g class=\"series\" data-renderer=\"{}\">", escape_html(s.name));
    if (s.model) o += curve_svg(f, s, s.fits ? 0 : unfit++);
    o += points_svg(f, s, kDodge * (double(i) - (n - 1) / 2)) + "</g>";
  }
  return o + "</g></svg>";
}

}  // namespace rvr::study
