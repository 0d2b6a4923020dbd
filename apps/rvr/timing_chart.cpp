// The timing chart (see timing_chart.h).
#include "timing_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "report_text.h"
#include "rvr/present/chart_axes.h"
#include "rvr/present/html_escape.h"
#include "rvr/present/legend.h"
#include "rvr/present/svg.h"

namespace rvr::report {
namespace {

// The phases of one renderer's bar in the timing chart, in pipeline order. time.load is the
// scene load (shared by every renderer, outside its render call); "other" is the part of the
// render call no phase accounts for. A phase nested in another (the BVH build is part of
// time.build) is left out of the stack so nothing is counted twice.
struct Phase {
  std::string name;  // "load", "render", ..., "other"
  double seconds = 0.0;
};

// The hybrid's time.render (the tracer's pixel-centre pass) is part of its time.trace (every
// traced and rebuilt ray), which stands beside time.zbuffer (its visibility passes). The
// tracers' time.shade is their time.render's share after the primary hits (softraster, which
// has no time.render, stacks its shading pass).
const std::map<std::string, std::string> kNestedPhases = {
    {"time.bvh_build", "time.build"}, {"time.render", "time.trace"}, {"time.shade", "time.render"}};

// Totals of other phases (softraster's time.visibility is time.setup + its clear +
// time.bin + time.raster; the tracers' is their time.render's share until the primary hits):
// never stacked.
const std::set<std::string> kTotalPhases = {"time.visibility"};

int phase_rank(const std::string& name) {
  static const char* order[] = {"load",    "setup",    "build",  "upload", "shadow_maps",
                                "zbuffer", "raster",   "render", "trace",  "shade",
                                "cost",    "readback", "write"};
  for (int i = 0; i < int(std::size(order)); ++i)
    if (name == order[i]) return i;
  return name == "other" ? 1000 : 100;
}

std::vector<Phase> phases_of(const ReportRenderer& r) {
  std::vector<Phase> phases;
  double in_call = 0.0;
  for (const auto& [key, value] : r.stats) {
    const auto nested = kNestedPhases.find(key);
    if (key.rfind("time.", 0) != 0 ||
        (nested != kNestedPhases.end() && r.stats.count(nested->second)) ||
        kTotalPhases.count(key) || !std::isfinite(value) || value < 0)
      continue;
    phases.push_back({key.substr(5), value});
    if (key != "time.load") in_call += value;
  }
  // Timer granularity and bookkeeping between phases: only a visible remainder is shown.
  const double other = r.seconds - in_call;
  if (std::isfinite(other) && other > 0.01 * r.seconds && other > 1e-6)
    phases.push_back({"other", other});
  std::stable_sort(phases.begin(), phases.end(), [](const Phase& a, const Phase& b) {
    return phase_rank(a.name) < phase_rank(b.name);
  });
  return phases;
}

// The colour of a phase's segments and of the label written on them: one colour per phase name
// across every bar, colour blind safe (Okabe-Ito, then Tol); grey for "other".
struct PhaseColour {
  const char* fill;
  const char* label;
};

PhaseColour phase_colour(const std::vector<std::string>& names, const std::string& name) {
  static const PhaseColour palette[] = {
      {"#0072b2", "#fff"},    {"#e69f00", "#1d2330"}, {"#009e73", "#fff"},
      {"#cc79a7", "#1d2330"}, {"#56b4e9", "#1d2330"}, {"#d55e00", "#fff"},
      {"#f0e442", "#1d2330"}, {"#332288", "#fff"},    {"#882255", "#fff"},
      {"#44aa99", "#1d2330"}, {"#999933", "#1d2330"}};
  if (name == "other") return {"#9aa3b5", "#1d2330"};
  const size_t i = std::find(names.begin(), names.end(), name) - names.begin();
  return palette[i % std::size(palette)];
}

// The chart's layout in SVG units: the bars' left edge and length, a row's and a bar's height.
constexpr double kLeft = 120, kBarLength = 640, kRow = 34, kBar = 22, kWidth = 880;

// The same numbers as the bars, as text for screen readers.
std::string description(const std::vector<ReportRenderer>& renderers,
                        const std::vector<std::vector<Phase>>& bars) {
  std::string desc;
  for (size_t i = 0; i < renderers.size(); ++i) {
    double total = 0.0;
    desc += (i ? "; " : "") + renderers[i].name + ":";
    for (const auto& p : bars[i]) {
      desc += " " + p.name + " " + fmt_s(p.seconds) + ",";
      total += p.seconds;
    }
    desc += " total " + fmt_s(total);
  }
  return desc;
}

// One renderer's bar at row `y`: its name, its phases stacked (each with a tooltip, and a label
// where it fits) and its total.
std::string bar_row(const ReportRenderer& r, const std::vector<Phase>& bar,
                    const std::vector<std::string>& names, const present::Scale& x, double y) {
  std::string o = present::text({{"class", "name"}, {"text-anchor", "end"}}, kLeft - 8,
                                y + kBar / 2 + 5, escape_html(r.name));
  double at = 0.0;
  for (const auto& p : bar) {
    const double x0 = x(at), x1 = x(at + p.seconds);
    at += p.seconds;
    const PhaseColour c = phase_colour(names, p.name);
    std::string tip = r.name + ": " + p.name + " " + fmt_s(p.seconds);
    for (const auto& [nested, parent] : kNestedPhases)
      if (auto it = r.stats.find(nested); parent == "time." + p.name && it != r.stats.end())
        tip += " (of which " + nested.substr(5) + " " + fmt_s(it->second) + ")";
    o += present::rect({{"data-phase", p.name}, {"fill", c.fill}}, x0, y, std::max(0.0, x1 - x0),
                       kBar, present::tooltip(tip));
    // A label only where it fits (about 6.5 units per character at 11 px).
    const std::string label = p.name + " " + fmt_s(p.seconds);
    if (x1 - x0 > 6.5 * double(label.size()) + 6)
      o += present::text({{"class", "seg"}, {"text-anchor", "middle"}, {"fill", c.label}},
                         (x0 + x1) / 2, y + kBar / 2 + 4, escape_html(label));
  }
  o += present::text({{"class", "total"}}, x(at) + 6, y + kBar / 2 + 5, fmt_s(at));
  return present::element("g", {{"class", "bar-row"}, {"data-renderer", r.name}}, o);
}

}  // namespace

std::string timing_chart(const std::vector<ReportRenderer>& renderers) {
  std::vector<std::vector<Phase>> bars;
  std::vector<std::string> names;  // every phase name, in pipeline order
  double top = 0.0;
  for (const auto& r : renderers) {
    bars.push_back(phases_of(r));
    double total = 0.0;
    for (const auto& p : bars.back()) {
      total += p.seconds;
      if (std::find(names.begin(), names.end(), p.name) == names.end()) names.push_back(p.name);
    }
    top = std::max(top, total);
  }
  std::stable_sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
    return phase_rank(a) < phase_rank(b);
  });
  if (!(top > 0.0)) top = 1.0;

  const present::PlotArea area{kLeft, 8, kLeft + kBarLength, 14 + kRow * double(renderers.size())};
  const present::Scale x = present::Scale::linear(0, present::nice_top(top), area.left, area.right);
  std::string o = present::chart_open({"timing-chart", "timing", kWidth, area.bottom + 44,
                                       "Time per phase of each renderer, in seconds",
                                       description(renderers, bars)});
  o += present::x_ticks(x, area, present::linear_ticks(top)) +
       present::axis_names(area, area.bottom + 36, "seconds", "");
  for (size_t i = 0; i < renderers.size(); ++i)
    o += bar_row(renderers[i], bars[i], names, x, 14 + kRow * double(i));
  o += "</svg>";
  std::vector<std::string> keys;
  keys.reserve(names.size());
  for (const auto& n : names)
    keys.push_back(present::swatch_key(phase_colour(names, n).fill, escape_html(n)));
  return "<figure class=\"chart-figure\">" + o + present::legend(keys) + "</figure>\n";
}

}  // namespace rvr::report
