// metrics.json and report.html of `rvr compare`.
//
// metrics.json holds exactly the fields cli.md requires, plus a few extras ("command",
// "heat_map_scale", "compared", "files", and "image" per renderer). JSON has no infinity or NaN:
// an infinite PSNR (identical colour) is written as 999.0, any other non-finite number as null.
//
// report.html is one self-contained file: the images are embedded as base64 data URIs, the CSS
// and the few lines of script are inline, nothing is fetched from anywhere.
#include "report.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
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
.grid{display:flex;flex-wrap:wrap;gap:16px}
figure{margin:0;background:#fff;padding:8px;border-radius:6px;
  box-shadow:0 1px 3px rgba(0,0,0,.12);flex:1 1 360px;max-width:calc(50% - 8px)}
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
th{background:#eef1f6;font-weight:600} td.num{text-align:right;font-variant-numeric:tabular-nums}
td.why{color:#4a5366;font-size:13px;max-width:560px}
details{margin:6px 0} summary{cursor:pointer;color:#2b3447}
footer{margin-top:30px;color:#7a8394;font-size:12px}
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
    // The float as it reads (0.1), not as its double widening prints (0.10000000149011612).
    const double scale = input.heat_map_scale;
    doc["heat_map_scale"] =
        number(std::isfinite(scale) ? std::strtod(fmt("%.7g", scale).c_str(), nullptr) : scale);
    doc["files"] = {
        {"diff", "diff.png"}, {"id_mismatch", "id_mismatch.png"}, {"report", "report.html"}};
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

    // Heat maps.
    h << "<h2>Differences</h2>\n<div class=\"grid\">\n"
      << "<figure><img src=\"" << diff_uri.value()
      << "\" alt=\"colour difference heat map\"><figcaption><b>diff.png</b>: per pixel, the "
         "largest |difference| over R, G, B of the linear colours, on the inferno colour map "
         "(black = 0, yellow-white &ge; "
      << fmt("%g", input.heat_map_scale) << ").</figcaption></figure>\n"
      << "<figure><img src=\"" << mismatch_uri.value()
      << "\" alt=\"object id mismatches\"><figcaption><b>id_mismatch.png</b>: pixels whose "
         "object id differs, in red, over a grey version of "
      << escape_html(name_a) << ".</figcaption></figure>\n</div>\n";

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
    h << "<h2>Timings</h2>\n<table><thead><tr><th>renderer</th><th>seconds</th>"
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
    h << "</tbody></table>\n<p class=\"why\" style=\"color:#4a5366;font-size:13px\">seconds: "
         "wall-clock time of the render call; relative: divided by the first renderer's; "
         "time.*: the phases each renderer reports.</p>\n";

    // All counters, folded away.
    for (const auto& r : input.renderers) {
      if (r.stats.empty()) continue;
      h << "<details><summary>All statistics of <b>" << escape_html(r.name) << "</b> ("
        << r.stats.size() << ")</summary><table><tbody>\n";
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
