// The charts' frame, scales and ticks (see chart_axes.h).
#include "rvr/present/chart_axes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "rvr/present/html_escape.h"
#include "rvr/present/powers_of_ten.h"
#include "rvr/present/svg.h"

namespace rvr::present {
namespace {

// Tick labels: this far below the plot (x) or left of it (y), in SVG units.
constexpr double kXLabelDrop = 18, kYLabelGap = 8;

}  // namespace

std::string chart_open(const ChartFrame& f) {
  const std::string id = escape_html(f.id);
  const bool described = !f.description.empty();
  std::string o = fmt::format(
      "<svg class=\"chart {}\" id=\"{}\" viewBox=\"0 0 {} {}\" role=\"img\" "
      "aria-labelledby=\"{}-title{}\"><title id=\"{}-title\">{}</title>",
      escape_html(f.kind), id, number(f.width), number(f.height), id,
      described ? " " + id + "-desc" : "", id, escape_html(f.title));
  if (described) o += fmt::format("<desc id=\"{}-desc\">{}</desc>", id, escape_html(f.description));
  return o;
}

Scale Scale::linear(double low, double high, double from, double to) {
  return Scale(low, high, from, to, false);
}

Scale Scale::log10(double low_exponent, double high_exponent, double from, double to) {
  return Scale(low_exponent, high_exponent, from, to, true);
}

double Scale::operator()(double v) const {
  const double at = log_ ? std::log10(v) : v;
  return from_ + (at - low_) / (high_ - low_) * (to_ - from_);
}

double nice_step(double top) {
  const double raw = top / 5.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0})
    if (raw <= m * magnitude) return m * magnitude;
  return 10.0 * magnitude;
}

double nice_top(double top) {
  const double step = nice_step(top);
  return std::ceil(top / step - 1e-9) * step;
}

std::vector<Tick> linear_ticks(double top) {
  const double step = nice_step(top), end = nice_top(top);
  std::vector<Tick> ticks;
  for (int k = 0; k * step <= end + 1e-12; ++k)
    ticks.push_back({k * step, fmt::format("{:g}", k * step)});
  return ticks;
}

std::vector<Tick> decade_ticks(int low, int high) {
  const int step = std::max(1, int(std::ceil((high - low) / 8.0)));
  std::vector<Tick> ticks;
  for (int k = low; k <= high; ++k) {
    ticks.push_back({std::pow(10.0, k), (k - low) % step == 0 ? decade_svg(k) : ""});
    for (int m = 2; m <= 9 && k < high && high - low <= 5; ++m)
      ticks.push_back({m * std::pow(10.0, k), "", true});
  }
  return ticks;
}

std::string x_ticks(const Scale& x, const PlotArea& area, const std::vector<Tick>& ticks) {
  std::string o;
  for (const Tick& t : ticks) {
    const double at = x(t.value);
    o += line({{"class", t.minor ? "minor" : "gridline"}}, at, area.top, at, area.bottom);
    if (!t.label.empty())
      o += text({{"class", "tick"}, {"text-anchor", "middle"}}, at, area.bottom + kXLabelDrop,
                t.label);
  }
  return o;
}

std::string y_ticks(const Scale& y, const PlotArea& area, const std::vector<Tick>& ticks) {
  std::string o;
  for (const Tick& t : ticks) {
    const double at = y(t.value);
    o += line({{"class", t.minor ? "minor" : "gridline"}}, area.left, at, area.right, at);
    if (!t.label.empty())
      o += text({{"class", "tick"}, {"text-anchor", "end"}}, area.left - kYLabelGap, at + 4,
                t.label);
  }
  return o;
}

std::string plot_frame(const PlotArea& area) {
  return rect({{"class", "plot"}}, area.left, area.top, area.width(), area.height());
}

std::string axis_names(const PlotArea& area, double baseline, const std::string& x_name,
                       const std::string& y_name) {
  std::string o;
  if (!x_name.empty())
    o += text({{"class", "axis-label"}, {"text-anchor", "middle"}}, (area.left + area.right) / 2,
              baseline, escape_html(x_name));
  if (!y_name.empty())
    o += element("text",
                 {{"class", "axis-label"},
                  {"transform", fmt::format("translate(16 {}) rotate(-90)",
                                            number((area.top + area.bottom) / 2))},
                  {"text-anchor", "middle"}},
                 escape_html(y_name));
  return o;
}

}  // namespace rvr::present
