// The timing chart (see timing_chart.h).
#include "timing_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <iterator>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "report_text.h"
#include "rvr/core/html_escape.h"

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

// A round axis step giving about 5 ticks up to `top`.
double nice_step(double top) {
  const double raw = top / 5.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0})
    if (raw <= m * mag) return m * mag;
  return 10.0 * mag;
}

}  // namespace

std::string timing_chart(const std::vector<ReportRenderer>& renderers) {
  // Colour blind safe (Okabe-Ito, then Tol), one colour per phase name across every bar; grey =
  // other.
  static const char* palette[][2] = {
      {"#0072b2", "#fff"},    {"#e69f00", "#1d2330"}, {"#009e73", "#fff"},
      {"#cc79a7", "#1d2330"}, {"#56b4e9", "#1d2330"}, {"#d55e00", "#fff"},
      {"#f0e442", "#1d2330"}, {"#332288", "#fff"},    {"#882255", "#fff"},
      {"#44aa99", "#1d2330"}, {"#999933", "#1d2330"}};
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
  auto colour = [&](const std::string& name) -> const char* const* {
    static const char* grey[2] = {"#9aa3b5", "#1d2330"};
    if (name == "other") return grey;
    size_t i = std::find(names.begin(), names.end(), name) - names.begin();
    return palette[i % std::size(palette)];
  };
  if (!(top > 0.0)) top = 1.0;
  const double step = nice_step(top);
  const double axis_top = std::ceil(top / step - 1e-9) * step;

  constexpr double kLeft = 120, kBarWidth = 640, kRow = 34, kBar = 22;
  const double height = 14 + kRow * double(renderers.size()) + 30;
  auto x_of = [&](double s) { return kLeft + s / axis_top * kBarWidth; };

  std::ostringstream desc;
  for (size_t i = 0; i < renderers.size(); ++i) {
    double total = 0.0;
    desc << (i ? "; " : "") << renderers[i].name << ":";
    for (const auto& p : bars[i]) {
      desc << " " << p.name << " " << fmt_s(p.seconds) << ",";
      total += p.seconds;
    }
    desc << " total " << fmt_s(total);
  }

  std::ostringstream o;
  o << "<svg id=\"timing-chart\" class=\"chart\" viewBox=\"0 0 880 " << height
    << "\" role=\"img\" aria-labelledby=\"timing-title timing-desc\">"
    << "<title id=\"timing-title\">Time per phase of each renderer, in seconds</title>"
    << "<desc id=\"timing-desc\">" << escape_html(desc.str()) << "</desc>";
  // Axis: grid lines and tick labels in seconds.
  const double axis_y = 14 + kRow * double(renderers.size());
  for (int k = 0; k * step <= axis_top + 1e-12; ++k) {
    const double x = x_of(k * step);
    o << "<line x1=\"" << x << "\" x2=\"" << x << "\" y1=\"8\" y2=\"" << axis_y
      << "\" stroke=\"#d8dce3\"/><text class=\"tick\" x=\"" << x << "\" y=\"" << axis_y + 16
      << "\" text-anchor=\"middle\">" << fmt("%g", k * step) << "</text>";
  }
  o << "<text class=\"tick\" x=\"" << kLeft - 8 << "\" y=\"" << axis_y + 16
    << "\" text-anchor=\"end\">seconds</text>";
  for (size_t i = 0; i < renderers.size(); ++i) {
    const double y = 14 + kRow * double(i);
    const std::string name = escape_html(renderers[i].name);
    o << "<g class=\"bar-row\" data-renderer=\"" << name << "\"><text class=\"name\" x=\""
      << kLeft - 8 << "\" y=\"" << y + kBar / 2 + 5 << "\" text-anchor=\"end\">" << name
      << "</text>";
    double at = 0.0;
    for (const auto& p : bars[i]) {
      const double x0 = x_of(at), x1 = x_of(at + p.seconds);
      at += p.seconds;
      const char* const* c = colour(p.name);
      std::string tip = renderers[i].name + ": " + p.name + " " + fmt_s(p.seconds);
      for (const auto& [nested, parent] : kNestedPhases)
        if (auto it = renderers[i].stats.find(nested);
            parent == "time." + p.name && it != renderers[i].stats.end())
          tip += " (of which " + nested.substr(5) + " " + fmt_s(it->second) + ")";
      o << "<rect data-phase=\"" << escape_html(p.name) << "\" x=\"" << x0 << "\" y=\"" << y
        << "\" width=\"" << std::max(0.0, x1 - x0) << "\" height=\"" << kBar << "\" fill=\"" << c[0]
        << "\"><title>" << escape_html(tip) << "</title></rect>";
      // A label only where it fits (about 6.5 px per character at 11 px).
      const std::string label = p.name + " " + fmt_s(p.seconds);
      if (x1 - x0 > 6.5 * double(label.size()) + 6)
        o << "<text class=\"seg\" x=\"" << (x0 + x1) / 2 << "\" y=\"" << y + kBar / 2 + 4
          << "\" text-anchor=\"middle\" fill=\"" << c[1] << "\">" << escape_html(label)
          << "</text>";
    }
    o << "<text class=\"total\" x=\"" << x_of(at) + 6 << "\" y=\"" << y + kBar / 2 + 5 << "\">"
      << fmt_s(at) << "</text></g>";
  }
  o << "</svg>\n<div class=\"legend\">";
  for (const auto& n : names)
    o << "<span><span class=\"sw\" style=\"background:" << colour(n)[0] << "\"></span>"
      << escape_html(n) << "</span>";
  o << "</div>\n";
  return o.str();
}

}  // namespace rvr::report
