// What every chart of a page shares: the <svg> with its accessible name, the plot area, linear
// and logarithmic scales, the ticks with their grid lines and labels, the axes' names. Drawn
// with the classes of the stylesheet (stylesheet.h): svg.chart, .plot, .gridline, .minor,
// .tick, .axis-label.
#pragma once

#include <string>
#include <vector>

namespace rvr::present {

// The opening <svg class="chart `kind`" id="`id`" ...> of a chart `width` × `height` SVG units
// that scales with the page, named by `title` (plain text) and described by `description`
// (plain text; none when empty) for screen readers. Close it with "</svg>".
struct ChartFrame {
  std::string id, kind;
  double width = 0, height = 0;
  std::string title, description;
};
std::string chart_open(const ChartFrame& frame);

// The rectangle the data is drawn in, in SVG units.
struct PlotArea {
  double left = 0, top = 0, right = 0, bottom = 0;
  double width() const { return right - left; }
  double height() const { return bottom - top; }
};

// Data to SVG units along one axis: [low, high] onto [from, to] (from > to for a y axis drawn
// upwards); logarithmic scales take low and high as powers of ten and values as they are.
class Scale {
 public:
  static Scale linear(double low, double high, double from, double to);
  static Scale log10(double low_exponent, double high_exponent, double from, double to);
  double operator()(double v) const;
  double low() const { return low_; }
  double high() const { return high_; }
  bool logarithmic() const { return log_; }

 private:
  Scale(double low, double high, double from, double to, bool log)
      : low_(low), high_(high), from_(from), to_(to), log_(log) {}
  double low_, high_, from_, to_;
  bool log_;
};

// A tick: where (in data units), its label (SVG text markup; none when empty) and whether it is
// a minor one (a fainter grid line, no label).
struct Tick {
  double value = 0;
  std::string label;
  bool minor = false;
};

// A round step giving about five ticks from 0 to `top`, and the axis' end: the first multiple
// of the step at or above `top`.
double nice_step(double top);
double nice_top(double top);
// 0, step, ... up to nice_top(top), labelled as %g.
std::vector<Tick> linear_ticks(double top);
// The decades 10^low ... 10^high, labelled 10^k (at most 8 labels), with minor ticks at 2..9
// times each decade when there are at most 5.
std::vector<Tick> decade_ticks(int low, int high);

// Vertical grid lines across `area` at the ticks of the x axis, labelled below it; horizontal
// ones at the ticks of the y axis, labelled left of it.
std::string x_ticks(const Scale& x, const PlotArea& area, const std::vector<Tick>& ticks);
std::string y_ticks(const Scale& y, const PlotArea& area, const std::vector<Tick>& ticks);

// The plot area's frame (rect.plot).
std::string plot_frame(const PlotArea& area);
// The axes' names (plain text): the x axis' centred under its tick labels at `baseline`, the
// y axis' turned upright at the chart's left edge; none where empty.
std::string axis_names(const PlotArea& area, double baseline, const std::string& x_name,
                       const std::string& y_name);

}  // namespace rvr::present
