// A log-log chart as inline SVG: measured points with their spread, model curves, and vertical
// marks with a shaded interval (crossovers). Private to the study library (study.html).
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace rvr::study {

// One measured point: its typical time and the fastest and slowest of its repetitions.
struct ChartPoint {
  double x = 0, typical = 0, low = 0, high = 0;
  std::string tooltip;  // plain text, escaped when drawn
};

// One renderer's points and its fitted model.
struct ChartSeries {
  std::string name, colour;
  std::vector<ChartPoint> points;
  std::function<double(double x)> model;  // null: no model to draw
  bool fits = false;                      // false: the curve is dashed and says so
};

// A vertical mark at `value` with its 95% interval shaded; a NaN or infinite end reaches the
// chart's edge on its side.
struct ChartCrossing {
  std::string tag;    // drawn at the top of the line: "1"
  std::string label;  // its tooltip: plain text, escaped when drawn
  double value = 0, low = 0, high = 0;
  bool measured = true;  // false: extrapolated, drawn dashed without a band of its own
};

struct ChartSpec {
  std::string id;                        // the svg element's id
  std::string title;                     // plain text: the chart's accessible name
  std::string x_label, y_label;          // plain text
  double swept_low = 0, swept_high = 0;  // outside this x range is shaded as not measured
  std::vector<ChartSeries> series;
  std::vector<ChartCrossing> crossings;
};

// The chart as an <svg class="study-chart"> element: decades ticked and labelled 10^k, the
// points as circle.mark (with a line.spread each) in a g.series per series, the models as
// path.model (or text.model-not-positive where a model has no positive time on the x axis), the
// crossings as g.crossover with rect.ci-band and line.crossover-line.
std::string loglog_chart_svg(const ChartSpec& spec);

}  // namespace rvr::study
