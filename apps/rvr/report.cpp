// metrics.json and report.html of `rvr compare`.
//
// metrics.json holds the fields docs/cli.md lists: the required ones plus a few extras ("command",
// "heat_map_scale", "depth_diff_scale", "compared", "files", and "image" per renderer). JSON
// has no infinity or NaN: an infinite PSNR (identical colour) is written as 999.0, any other
// non-finite number as null.
//
// report.html is one self-contained file: the images are embedded as base64 data URIs, the CSS
// and the few lines of script are inline, nothing is fetched from anywhere.
#include "report.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace rvr {
namespace {

using ordered_json = nlohmann::ordered_json;

constexpr double kPsnrIdentical = 999.0;  // stands for +inf in metrics.json

ordered_json number(double v) {
  return std::isfinite(v) ? ordered_json(v) : ordered_json(nullptr);
}

std::string fmt(const char* format, double v);

// The float as it reads (0.1), not as its double widening prints (0.10000000149011612).
ordered_json float_number(float v) {
  return number(std::isfinite(v) ? std::strtod(fmt("%.7g", v).c_str(), nullptr) : v);
}

ordered_json psnr_number(double v) {
  if (std::isinf(v) && v > 0) return kPsnrIdentical;
  return number(v);
}

std::string escape_html(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string mime_type(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  if (ext == ".gif") return "image/gif";
  if (ext == ".webp") return "image/webp";
  if (ext == ".bmp") return "image/bmp";
  return "application/octet-stream";
}

// The data URI of out_dir/file, or an error naming the path.
Expected<std::string> data_uri(const std::string& out_dir, const std::string& file) {
  std::string path = (std::filesystem::path(out_dir) / file).string();
  std::ifstream in(path, std::ios::binary);
  if (!in) return internal_error("cannot read '" + path + "': no such file or not readable");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return internal_error("cannot read '" + path + "': read failed");
  return "data:" + mime_type(file) + ";base64," + base64(bytes);
}

std::string fmt(const char* format, double v) {
  if (std::isnan(v)) return "n/a";
  if (std::isinf(v)) return v > 0 ? "&infin;" : "&minus;&infin;";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string fmt_seconds(double s) {
  if (!std::isfinite(s)) return fmt("%g", s);
  if (s < 1e-3) return fmt("%.1f &micro;s", s * 1e6);
  if (s < 1.0) return fmt("%.2f ms", s * 1e3);
  return fmt("%.3f s", s);
}

// A number as people write it: 1e-6 rather than 1e-06 or 9.99999997e-07 (a float widened), and
// powers of ten of one form (1e-2 next to 1e-5, not 0.01).
std::string short_number(double v) {
  if (v > 0 && std::isfinite(v)) {
    const double e = std::round(std::log10(v));
    if (std::fabs(v / std::pow(10.0, e) - 1.0) < 1e-6 && std::fabs(e) >= 2)
      return "1e" + std::to_string(int(e));
  }
  std::string t = fmt("%.6g", v);
  for (const char* from : {"e-0", "e+0", "e+"}) {
    size_t at = t.find(from);
    if (at != std::string::npos) t.replace(at, std::strlen(from), from[1] == '-' ? "e-" : "e");
  }
  return t;
}

// Seconds as the timing chart labels them: three significant digits, always in seconds.
std::string fmt_s(double s) {
  return fmt("%.3g s", s);
}

// OpenImageIO's / matplotlib's inferno map at 0, 0.1, ..., 1 (sRGB), for the colour bars.
const char* kInfernoStops[] = {"#000004", "#160b39", "#420a68", "#6a176e", "#932667", "#bc3754",
                               "#dd513a", "#f37819", "#fca50a", "#f6d746", "#fcffa4"};

// An inline SVG colour bar of the inferno map with labelled ticks (position in [0, 1], text),
// so a heat map can be read without the caption.
std::string inferno_bar(const std::string& id, const std::string& label,
                        const std::vector<std::pair<double, std::string>>& ticks) {
  constexpr double kX0 = 10, kWidth = 300;
  std::ostringstream o;
  o << "<svg class=\"bar\" viewBox=\"0 0 320 40\" width=\"320\" height=\"40\" role=\"img\" "
       "aria-label=\""
    << escape_html(label) << "\"><defs><linearGradient id=\"" << id << "\">";
  for (int i = 0; i <= 10; ++i)
    o << "<stop offset=\"" << i * 10 << "%\" stop-color=\"" << kInfernoStops[i] << "\"/>";
  o << "</linearGradient></defs><rect x=\"" << kX0 << "\" y=\"2\" width=\"" << kWidth
    << "\" height=\"14\" fill=\"url(#" << id << ")\" stroke=\"#9aa3b5\" stroke-width=\"0.5\"/>";
  for (const auto& [pos, text] : ticks) {
    const double x = kX0 + pos * kWidth;
    o << "<line x1=\"" << x << "\" x2=\"" << x << "\" y1=\"16\" y2=\"21\" stroke=\"#4a5366\"/>"
      << "<text x=\"" << x << "\" y=\"33\" text-anchor=\""
      << (pos < 0.01   ? "start"
          : pos > 0.99 ? "end"
                       : "middle")
      << "\">" << text << "</text>";
  }
  o << "</svg>";
  return o.str();
}

// A colour swatch as the captions use it.
std::string swatch(const float rgb[3]) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "<span class=\"sw\" style=\"background:#%02x%02x%02x\"></span>",
                int(std::lround(rgb[0] * 255)), int(std::lround(rgb[1] * 255)),
                int(std::lround(rgb[2] * 255)));
  return buf;
}

// The phases of one renderer's bar in the timing chart, in pipeline order. time.load is the
// scene load (shared by every renderer, outside its render call); "other" is the part of the
// render call no phase accounts for. A phase nested in another (the BVH build is part of
// time.build) is left out of the stack so nothing is counted twice.
struct Phase {
  std::string name;  // "load", "render", ..., "other"
  double seconds = 0.0;
};

const std::map<std::string, std::string> kNestedPhases = {{"time.bvh_build", "time.build"}};

int phase_rank(const std::string& name) {
  static const char* order[] = {"load",   "setup", "build", "upload",   "shadow_maps", "raster",
                                "render", "shade", "cost",  "readback", "write"};
  for (int i = 0; i < int(std::size(order)); ++i)
    if (name == order[i]) return i;
  return name == "other" ? 1000 : 100;
}

std::vector<Phase> phases_of(const ReportRenderer& r) {
  std::vector<Phase> phases;
  double in_call = 0.0;
  for (const auto& [key, value] : r.stats) {
    if (key.rfind("time.", 0) != 0 || kNestedPhases.count(key) || !std::isfinite(value) ||
        value < 0)
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

// Inline SVG: per renderer one horizontal bar of its phases stacked, with labels and seconds;
// a <title> and <desc> carry the same numbers as text for screen readers, and every segment
// has a tooltip.
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
      if (p.name == "build")
        for (const auto& [nested, parent] : kNestedPhases)
          if (auto it = renderers[i].stats.find(nested);
              parent == "time.build" && it != renderers[i].stats.end())
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

const char* kCss = R"(
body{font:15px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:0;
  background:#f6f7f9;color:#1d2330}
main{max-width:1400px;margin:0 auto;padding:24px}
h1{font-size:24px;margin:0 0 4px} h2{font-size:18px;margin:28px 0 10px;
  border-bottom:1px solid #d8dce3;padding-bottom:4px}
pre.cmd{background:#1d2330;color:#e8ecf3;padding:10px 12px;border-radius:6px;
  overflow-x:auto;white-space:pre-wrap;word-break:break-all}
.meta span{display:inline-block;margin-right:18px;color:#4a5366}
.badges{margin:10px 0}
.badge{display:inline-block;padding:3px 10px;border-radius:12px;margin:0 6px 6px 0;
  font-weight:600;font-size:13px}
.good{background:#d9f2e1;color:#135c2c} .bad{background:#fbdcdc;color:#8a1616}
.neutral{background:#e3e8f0;color:#2b3447}
.warn{background:#fff4d6;border:1px solid #e6b400;border-left:6px solid #e6b400;
  padding:10px 14px;border-radius:6px;margin:14px 0}
.warn h2{border:0;margin:0 0 6px;padding:0}
.grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(360px,1fr));gap:16px}
figure{margin:0;background:#fff;padding:8px;border-radius:6px;
  box-shadow:0 1px 3px rgba(0,0,0,.12);min-width:0}
figure img{display:block;width:100%;height:auto;image-rendering:pixelated}
figcaption{font-size:13px;color:#4a5366;margin-top:6px}
.flip{position:relative;display:block;width:100%;user-select:none}
.flip img{display:block;width:100%;height:auto;image-rendering:pixelated}
.flip img.top{position:absolute;left:0;top:0}
.flipctl{display:flex;align-items:center;gap:10px;margin-top:6px;font-size:13px}
.flipctl input{flex:1}
button{font:inherit;font-size:13px;padding:2px 10px;border-radius:4px;
  border:1px solid #9aa3b5;background:#fff;cursor:pointer}
table{border-collapse:collapse;background:#fff;box-shadow:0 1px 3px rgba(0,0,0,.12);
  border-radius:6px;overflow:hidden;margin-bottom:8px}
th,td{padding:5px 12px;border-bottom:1px solid #e6e9ef;text-align:left;vertical-align:top}
th{background:#eef1f6;font-weight:600} td.num{text-align:right;font-variant-numeric:tabular-nums;
  white-space:nowrap}
.scroll{overflow-x:auto;max-width:100%} .nowrap{white-space:nowrap}
td.why{color:#4a5366;font-size:13px;max-width:560px}
details{margin:6px 0} summary{cursor:pointer;color:#2b3447}
footer{margin-top:30px;color:#7a8394;font-size:12px}
svg.bar{display:block;margin-top:4px;font-size:11px;fill:#4a5366}
.sw{display:inline-block;width:11px;height:11px;border:1px solid #9aa3b5;
  vertical-align:-1px;margin-right:4px}
svg.chart{display:block;width:100%;max-width:1000px;background:#fff;border-radius:6px;
  box-shadow:0 1px 3px rgba(0,0,0,.12);font-size:12px}
svg.chart text{fill:#1d2330} svg.chart text.tick{fill:#4a5366;font-size:11px}
svg.chart text.name{font-weight:600} svg.chart text.seg{font-size:11px}
.legend{display:flex;flex-wrap:wrap;gap:14px;margin:8px 0 14px;font-size:13px;color:#4a5366}
)";

// Flip / slider between the first two renders: the top image is clipped from the left.
const char* kScript = R"(
(function () {
  var range = document.getElementById('flip-range');
  var upper = document.getElementById('flip-top');
  var button = document.getElementById('flip-button');
  if (!range || !upper || !button) return;
  function show(v) { upper.style.clipPath = 'inset(0 0 0 ' + v + '%)'; }
  range.addEventListener('input', function () { show(range.value); });
  button.addEventListener('click', function () {
    range.value = Number(range.value) < 50 ? 100 : 0;
    show(range.value);
  });
  show(range.value);
})();
)";

struct MetricRow {
  std::string group, name, value, why;
  bool flagged = false;
};

}  // namespace

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    unsigned v = (unsigned(uint8_t(bytes[i])) << 16) | (unsigned(uint8_t(bytes[i + 1])) << 8) |
                 unsigned(uint8_t(bytes[i + 2]));
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += table[v & 63];
  }
  if (size_t rest = bytes.size() - i; rest > 0) {
    unsigned v = unsigned(uint8_t(bytes[i])) << 16;
    if (rest == 2) v |= unsigned(uint8_t(bytes[i + 1])) << 8;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += rest == 2 ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string metrics_json(const ReportInput& input) {
  try {
    ordered_json doc;
    doc["scene"] = input.scene;
    doc["width"] = input.width;
    doc["height"] = input.height;
    doc["mode"] = input.mode;

    ordered_json renderers = ordered_json::object();
    ordered_json compared = ordered_json::array();
    for (const auto& r : input.renderers) {
      std::string key = r.name;
      for (int k = 2; renderers.contains(key); ++k) key = r.name + "-" + std::to_string(k);
      ordered_json stats = ordered_json::object();
      for (const auto& [name, value] : r.stats) stats[name] = number(value);
      renderers[key] = {{"seconds", number(r.seconds)},
                        {"warnings", r.warnings},
                        {"stats", stats},
                        {"info", r.info},
                        {"image", r.image_file}};
      if (!r.cost_file.empty())
        renderers[key]["cost"] = {
            {"image", r.cost_file}, {"mean", number(r.cost_mean)}, {"scale", number(r.cost_scale)}};
      if (compared.size() < 2) compared.push_back(key);
    }
    doc["renderers"] = renderers;

    const auto& v = input.metrics.visibility;
    doc["visibility"] = {{"pixels", v.pixels},
                         {"id_agreement", number(v.id_agreement)},
                         {"mismatched_pixels", v.mismatched_pixels},
                         {"mismatched_off_edge", v.mismatched_off_edge}};
    const auto& d = input.metrics.depth;
    doc["depth"] = {{"max_rel_error", number(d.max_rel_error)},
                    {"mean_rel_error", number(d.mean_rel_error)}};
    const auto& c = input.metrics.color;
    doc["color"] = {{"rmse", number(c.rmse)},
                    {"psnr_db", psnr_number(c.psnr_db)},
                    {"max_abs", number(c.max_abs)},
                    {"ssim", number(c.ssim)}};

    // Extras.
    doc["compared"] = compared;
    doc["command"] = input.command_line;
    doc["heat_map_scale"] = float_number(input.heat_map_scale);
    doc["depth_diff_scale"] = {{"low", float_number(input.depth_diff_scale.low)},
                               {"high", float_number(input.depth_diff_scale.high)},
                               {"map", "log10"}};
    doc["files"] = {{"diff", "diff.png"},
                    {"depth_diff", "depth_diff.png"},
                    {"id_mismatch", "id_mismatch.png"},
                    {"report", "report.html"}};
    // Invalid UTF-8 in a path or command line must not make dump() throw.
    return doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  } catch (const std::exception& e) {
    // Only allocation failure can get here; still hand back valid JSON.
    ordered_json err = {{"error", std::string("metrics_json failed: ") + e.what()}};
    return err.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  }
}

Expected<std::string> report_html(const ReportInput& input) {
  try {
    const auto& vis = input.metrics.visibility;
    const auto& dep = input.metrics.depth;
    const auto& col = input.metrics.color;
    const std::string name_a = input.renderers.size() > 0 ? input.renderers[0].name : "A";
    const std::string name_b = input.renderers.size() > 1 ? input.renderers[1].name : "B";

    // Every image first, so a missing file fails before any HTML is built.
    std::vector<std::string> render_uris;
    for (const auto& r : input.renderers) {
      auto uri = data_uri(input.out_dir, r.image_file);
      if (!uri) return uri.error();
      render_uris.push_back(std::move(uri.value()));
    }
    std::vector<std::string> cost_uris;
    for (const auto& r : input.renderers) {
      if (r.cost_file.empty()) {
        cost_uris.emplace_back();
        continue;
      }
      auto uri = data_uri(input.out_dir, r.cost_file);
      if (!uri) return uri.error();
      cost_uris.push_back(std::move(uri.value()));
    }
    auto diff_uri = data_uri(input.out_dir, "diff.png");
    if (!diff_uri) return diff_uri.error();
    auto mismatch_uri = data_uri(input.out_dir, "id_mismatch.png");
    if (!mismatch_uri) return mismatch_uri.error();
    auto depth_uri = data_uri(input.out_dir, "depth_diff.png");
    if (!depth_uri) return depth_uri.error();

    std::ostringstream h;
    const std::string title = "rvr compare: " + name_a + " vs " + name_b + " on " + input.scene;
    h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      << "<title>" << escape_html(title) << "</title>\n<style>" << kCss << "</style>\n"
      << "</head>\n<body>\n<main>\n";

    h << "<h1>" << escape_html(title) << "</h1>\n";
    h << "<div class=\"meta\"><span><b>scene</b> " << escape_html(input.scene)
      << "</span><span><b>size</b> " << input.width << "&times;" << input.height
      << "</span><span><b>mode</b> " << escape_html(input.mode) << "</span><span><b>pixels</b> "
      << vis.pixels << "</span></div>\n";
    if (!input.command_line.empty())
      h << "<pre class=\"cmd\">" << escape_html(input.command_line) << "</pre>\n";

    // Verdict badges.
    h << "<div class=\"badges\">"
      << "<span class=\"badge " << (vis.mismatched_off_edge == 0 ? "good" : "bad") << "\">"
      << "mismatched off edges: " << vis.mismatched_off_edge << "</span>"
      << "<span class=\"badge neutral\">id agreement " << fmt("%.4f", vis.id_agreement * 100.0)
      << "%</span>"
      << "<span class=\"badge neutral\">PSNR "
      << (std::isinf(col.psnr_db) && col.psnr_db > 0 ? std::string("&infin; (identical)")
                                                     : fmt("%.2f dB", col.psnr_db))
      << "</span><span class=\"badge neutral\">SSIM " << fmt("%.5f", col.ssim) << "</span></div>\n";

    // Warnings, prominently.
    size_t warning_count = 0;
    for (const auto& r : input.renderers) warning_count += r.warnings.size();
    if (warning_count > 0) {
      h << "<div class=\"warn\"><h2>&#9888; Warnings (" << warning_count << ")</h2><ul>\n";
      for (const auto& r : input.renderers)
        for (const auto& w : r.warnings)
          h << "<li><b>" << escape_html(r.name) << "</b>: " << escape_html(w) << "</li>\n";
      h << "</ul></div>\n";
    }

    // Renders side by side.
    h << "<h2>Renders</h2>\n<div class=\"grid\">\n";
    for (size_t i = 0; i < input.renderers.size(); ++i) {
      const auto& r = input.renderers[i];
      h << "<figure><img src=\"" << render_uris[i] << "\" alt=\"" << escape_html(r.name)
        << "\"><figcaption><b>" << escape_html(r.name) << "</b> &middot; "
        << escape_html(r.image_file) << " &middot; " << fmt_seconds(r.seconds)
        << "</figcaption></figure>\n";
    }
    h << "</div>\n";

    if (input.renderers.size() >= 2) {
      h << "<h2>Flip</h2>\n<div class=\"grid\"><figure><div class=\"flip\">"
        << "<img src=\"" << render_uris[0] << "\" alt=\"" << escape_html(name_a) << "\">"
        << "<img id=\"flip-top\" class=\"top\" src=\"" << render_uris[1] << "\" alt=\""
        << escape_html(name_b) << "\"></div>"
        << "<div class=\"flipctl\"><span>" << escape_html(name_a)
        << "</span><input id=\"flip-range\" type=\"range\" min=\"0\" max=\"100\" value=\"50\" "
        << "aria-label=\"slider between the two renders\"><span>" << escape_html(name_b)
        << "</span><button id=\"flip-button\" type=\"button\">flip</button></div>"
        << "<figcaption>Left of the cut: " << escape_html(name_a)
        << "; right of it: " << escape_html(name_b)
        << ". Drag the slider, or flip between the whole images.</figcaption></figure></div>\n";
    }

    // Heat maps. The depth scale's decades as ticks of its colour bar.
    const double low = input.depth_diff_scale.low, high = input.depth_diff_scale.high;
    std::vector<std::pair<double, std::string>> depth_ticks;
    if (low > 0 && high > low) {
      const double decades = std::log10(high / low);
      // The ends are floats: 1e-2f is 0.0099999998, still a tick.
      for (double e = std::ceil(std::log10(low) - 1e-6); e <= std::log10(high) + 1e-6; e += 1)
        depth_ticks.push_back({(e - std::log10(low)) / decades, short_number(std::pow(10.0, e))});
    }
    h << "<h2>Differences</h2>\n<div class=\"grid\">\n"
      << "<figure><img src=\"" << diff_uri.value()
      << "\" alt=\"colour difference heat map\"><figcaption><b>diff.png</b>: per pixel, the "
         "largest |difference| over R, G, B of the linear colours, on the inferno colour map "
         "(black = 0, yellow-white &ge; "
      << fmt("%g", input.heat_map_scale) << ")."
      << inferno_bar("bar-diff", "colour difference scale",
                     {{0.0, "0"},
                      {0.5, fmt("%g", input.heat_map_scale / 2)},
                      {1.0, "&ge; " + fmt("%g", input.heat_map_scale)}})
      << "</figcaption></figure>\n"
      << "<figure><img src=\"" << mismatch_uri.value()
      << "\" alt=\"object id mismatches\"><figcaption><b>id_mismatch.png</b>: pixels whose "
         "object id differs, in red, over a grey version of "
      << escape_html(name_a) << ".</figcaption></figure>\n"
      << "<figure><img src=\"" << depth_uri.value()
      << "\" alt=\"relative depth difference\"><figcaption><b>depth_diff.png</b>: relative "
         "view-depth difference |d<sub>A</sub> &minus; d<sub>B</sub>| / max(d<sub>A</sub>, "
         "d<sub>B</sub>) of "
      << escape_html(name_a) << " and " << escape_html(name_b)
      << " where both hit something (whatever the ids), on a <b>log scale</b>: black &le; "
      << short_number(low) << ", each decade an equal stretch of the colour map, yellow-white "
      << "&ge; " << short_number(high) << ". <span class=\"nowrap\">"
      << swatch(kDepthDiffBackground) << "background in both</span>; <span class=\"nowrap\">"
      << swatch(kDepthDiffHitVsBackground) << "background in one, a hit in the other</span>."
      << inferno_bar("bar-depth", "relative depth difference scale, logarithmic", depth_ticks)
      << "</figcaption></figure>\n</div>\n";

    // Work per pixel: what each loop order pays where.
    h << "<h2>Work per pixel</h2>\n<div class=\"grid\">\n";
    for (size_t i = 0; i < input.renderers.size(); ++i) {
      const auto& r = input.renderers[i];
      if (r.cost_file.empty()) {
        h << "<figure><figcaption><b>" << escape_html(r.name)
          << "</b>: no per-pixel work reported.</figcaption></figure>\n";
        continue;
      }
      h << "<figure><img src=\"" << cost_uris[i] << "\" alt=\"" << escape_html(r.name)
        << " work per pixel\"><figcaption><b>" << escape_html(r.cost_file) << "</b>: "
        << (r.stats.count("fragments.generated") ? "fragments generated per pixel (overdraw)"
                                                 : "BVH nodes visited + primitive tests per pixel")
        << "; mean " << fmt("%.3g", r.cost_mean) << ", yellow-white &ge; "
        << fmt("%g", r.cost_scale) << " (the 99th percentile).</figcaption></figure>\n";
    }
    h << "</div>\n";

    // Metrics.
    const bool identical = std::isinf(col.psnr_db) && col.psnr_db > 0;
    std::vector<MetricRow> rows = {
        {"visibility", "pixels", std::to_string(vis.pixels), "width &times; height."},
        {"visibility", "id_agreement", fmt("%.6f", vis.id_agreement),
         "Fraction of pixels where both renders see the same object and the same primitive."},
        {"visibility", "mismatched_pixels", std::to_string(vis.mismatched_pixels),
         "Pixels whose (object, primitive) id differs."},
        {"visibility", "mismatched_off_edge", std::to_string(vis.mismatched_off_edge),
         "Mismatches with no id boundary within one pixel in both renders: not a silhouette or "
         "edge tie, so a real disagreement. Should be 0.",
         vis.mismatched_off_edge != 0},
        {"depth", "max_rel_error", fmt("%.3g", dep.max_rel_error),
         "Largest |d<sub>A</sub> &minus; d<sub>B</sub>| / max(d<sub>A</sub>, d<sub>B</sub>) of "
         "view-axis depth over pixels where the ids agree (background excluded)."},
        {"depth", "mean_rel_error", fmt("%.3g", dep.mean_rel_error),
         "Mean of the same relative depth error."},
        {"color", "rmse", fmt("%.4g", col.rmse),
         "Root mean square difference of linear RGB over every pixel and channel."},
        {"color", "psnr_db",
         identical ? std::string("&infin; (999 in metrics.json)") : fmt("%.2f", col.psnr_db),
         "20&middot;log<sub>10</sub>(1 / rmse), peak value 1; higher is closer. Identical images "
         "have infinite PSNR, written as 999 in metrics.json."},
        {"color", "max_abs", fmt("%.4g", col.max_abs),
         "Largest absolute difference of one channel of one pixel (linear)."},
        {"color", "ssim", fmt("%.5f", col.ssim),
         "Structural similarity of the luminance of the colours clamped to [0, 1], 11&times;11 "
         "Gaussian window (&sigma; 1.5), averaged over the image; 1 = identical."},
    };
    h << "<h2>Metrics</h2>\n<table><thead><tr><th>group</th><th>metric</th><th>value</th>"
         "<th>meaning</th></tr></thead><tbody>\n";
    for (const auto& row : rows)
      h << "<tr><td>" << row.group << "</td><td><code>" << row.name << "</code></td><td class=\"num"
        << (row.flagged ? " bad" : "") << "\">" << row.value << "</td><td class=\"why\">" << row.why
        << "</td></tr>\n";
    h << "</tbody></table>\n";

    // Timings: seconds and every "time.*" stat, one row per renderer.
    std::set<std::string> time_keys;
    for (const auto& r : input.renderers)
      for (const auto& [k, v] : r.stats)
        if (k.rfind("time.", 0) == 0) time_keys.insert(k);
    h << "<h2>Timings</h2>\n"
      << timing_chart(input.renderers)
      << "<p class=\"why\" style=\"color:#4a5366;font-size:13px\">Each bar: the scene load "
         "(shared, outside the render call), the phases the renderer reports (time.* below) "
         "and, as <i>other</i>, the rest of its render call.</p>\n"
      << "<div class=\"scroll\"><table><thead><tr><th>renderer</th><th>seconds</th>"
         "<th>relative</th>";
    for (const auto& k : time_keys) h << "<th>" << escape_html(k) << "</th>";
    h << "<th>warnings</th></tr></thead><tbody>\n";
    const double base = input.renderers.empty() ? 0.0 : input.renderers[0].seconds;
    for (const auto& r : input.renderers) {
      h << "<tr><td><b>" << escape_html(r.name) << "</b></td><td class=\"num\">"
        << fmt_seconds(r.seconds) << "</td><td class=\"num\">"
        << (base > 0 ? fmt("%.2f&times;", r.seconds / base) : std::string("n/a")) << "</td>";
      for (const auto& k : time_keys) {
        auto it = r.stats.find(k);
        h << "<td class=\"num\">" << (it == r.stats.end() ? "&ndash;" : fmt_seconds(it->second))
          << "</td>";
      }
      h << "<td class=\"num\">" << r.warnings.size() << "</td></tr>\n";
    }
    h << "</tbody></table></div>\n<p class=\"why\" style=\"color:#4a5366;font-size:13px\">seconds: "
         "wall-clock time of the render call; relative: divided by the first renderer's; "
         "time.*: the phases each renderer reports.</p>\n";

    // All counters, folded away.
    for (const auto& r : input.renderers) {
      if (r.stats.empty()) continue;
      h << "<details><summary>All statistics of <b>" << escape_html(r.name) << "</b> ("
        << r.stats.size() << ")</summary><table><tbody>\n";
      for (const auto& [k, v] : r.info)
        h << "<tr><td><code>" << escape_html(k) << "</code></td><td class=\"num\">"
          << escape_html(v) << "</td></tr>\n";
      for (const auto& [k, v] : r.stats)
        h << "<tr><td><code>" << escape_html(k) << "</code></td><td class=\"num\">"
          << fmt("%.6g", v) << "</td></tr>\n";
      h << "</tbody></table></details>\n";
    }

    h << "<footer>Written by rvr compare. Colour metrics use linear RGB with peak 1; the "
         "heat map scale is "
      << fmt("%g", input.heat_map_scale) << ".</footer>\n</main>\n";
    if (input.renderers.size() >= 2) h << "<script>" << kScript << "</script>\n";
    h << "</body>\n</html>\n";
    return h.str();
  } catch (const std::exception& e) {
    return internal_error(std::string("cannot build report.html: ") + e.what());
  }
}

}  // namespace rvr
