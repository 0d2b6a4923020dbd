// Sentences and tables of the counted work (see counted_work_text.h).
#include "counted_work_text.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "rvr/present/html_escape.h"
#include "rvr/present/powers_of_ten.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/counted_work.h"
#include "rvr/study/crossover.h"
#include "rvr/study/fit.h"
#include "rvr/study/study_markdown.h"

namespace rvr::study {
namespace {

using present::escape_html;
using present::html_with_powers;

// A count grows "in proportion" to an axis from this log-log slope up, is "flat" up to this one.
constexpr double kProportional = 0.9;
constexpr double kFlat = 0.1;
// A quantity is "linear" in its x from this R² of the line up.
constexpr double kLinear = 0.9;

const char* const kWorkIntro =
    "Frame time as a constant plus a non-negative cost per counted item, t = u0 + Σ u·count, "
    "fitted to every point of the renderer's family (the sweep along N and the pixel sweep). "
    "docs/cli.md says what each count counts; a count absent, the same at every point or "
    "following the counts before it is left out.";
const char* const kClaimsIntro =
    "The chapter's claims checked on the renderers' own counts, which are exact and the same on "
    "every machine.";
const char* const kTablesIntro =
    "Each count's log-log slope (count ∝ axis^slope) against N at the full image size and "
    "against the pixel count at each N of the pixel sweep, with the R² of that line.";

// "15.7 ns (95%: 13.4 – 18.8) × pixels", or for the constant "0.063 ms (95%: …)".
std::string term_text(const Coefficient& c, bool constant) {
  const double f = constant ? 1e3 : 1e9;
  const std::string value =
      fmt::format("{} {} (95%: {} – {})", format_number(f * c.value), constant ? "ms" : "ns",
                  format_number(f * c.ci95.low), format_number(f * c.ci95.high));
  return constant ? value : value + " × " + c.name;
}

std::string work_sentence(const WorkModel& m) {
  std::string left_out;
  for (const LeftOutCounter& l : m.left_out)
    left_out += (left_out.empty() ? " Left out: " : "; ") + l.counter + " (" + l.why + ")";
  if (!left_out.empty()) left_out += ".";
  if (!m.fits) {
    std::string counts;
    for (size_t j = 1; j < m.terms.size(); ++j)
      counts += (counts.empty() ? "" : ", ") + m.terms[j].name;
    return fmt::format(
        "{} on {}: the model from counted work ({}) {}; no unit cost is read from "
        "it.{}",
        m.renderer, m.scene, counts.empty() ? "a constant only" : counts, m.verdict, left_out);
  }
  std::string terms;
  for (size_t j = 0; j < m.terms.size(); ++j)
    terms += (j ? " + " : "") + term_text(m.terms[j], j == 0);
  return fmt::format(
      "{} on {} ({} points): t = {}; R² {:.3f}, largest residual {:.0f}%, leave-one-out error "
      "{:.0f}% (median); scatter about the model beyond the timing noise {:.1f}% (timing noise "
      "{:.1f}%).{}",
      m.renderer, m.scene, m.points, terms, m.r2, 100 * m.max_rel_residual, 100 * m.loo_rel_error,
      100 * m.misfit, 100 * m.repetition_noise, left_out);
}

// How a count grows along its axis, from its log-log slope.
std::string growth(double exponent, const std::string& axis) {
  if (exponent >= kProportional) return "in proportion to " + axis;
  if (exponent <= kFlat) return "flat";
  return fmt::format("as {}^{:.2f}", axis, exponent);
}

std::string claim_sentence(const StudyResult& r, const CountClaim& c) {
  const std::string axis = r.axes.count(c.scene) ? r.axes.at(c.scene) : "";
  const std::string range =
      fmt::format("{} – {} {}", format_number(c.from), format_number(c.to), axis);
  const std::string line =
      fmt::format("{:.4g} + {:.4g}·{} (R² {:.3f})", c.intercept, c.slope, c.against, c.r2);
  if (c.claim == "nodes_per_ray") {
    std::string reading =
        c.slope > 0 && c.r2 >= kLinear
            ? "linear in log2 N: each ray visits O(log N) nodes, the tree's early rejection"
        : c.slope <= 0 ? "it does not grow with log2 N"
                       : "not a line in log2 N";
    return fmt::format(
        "{} on {}: BVH nodes visited per ray = {} over {}: {} (log-log slope "
        "against N {:.2f}).",
        c.renderer, c.scene, line, range, reading, c.exponent);
  }
  if (c.claim == "fragments_per_pixel") {
    std::string reading =
        c.exponent >= kProportional ? "they grow with D as the textbook z-buffer's P·D fragments"
        : c.exponent <= kFlat
            ? "flat: the hidden layers' pixels are not tested, where the textbook z-buffer tests "
              "P·D fragments"
            : fmt::format("they grow as D^{:.2f}, between flat and the textbook's P·D", c.exponent);
    return fmt::format("{} on {}: fragments tested per pixel ({}) = {} over {}: {}.", c.renderer,
                       c.scene, c.quantity, line, range, reading);
  }
  return fmt::format(
      "{} on {}: {} grows {} (log-log slope {:.2f}) over {}; the line {} says {:.3g} set up per "
      "triangle added.",
      c.renderer, c.scene, c.quantity, growth(c.exponent, "N"), c.exponent, range, line, c.slope);
}

std::string markdown_table(const CountTable& t) {
  auto row = [](const std::vector<std::string>& cells) {
    std::string s = "|";
    for (const std::string& c : cells) s += " " + c + " |";
    return s + "\n";
  };
  std::string text = "\n### " + t.scene + "\n\n" + row(t.header);
  text += row(std::vector<std::string>(t.header.size(), "---"));
  for (const auto& r : t.rows) text += row(r);
  return text;
}

std::string list_markdown(const std::string& heading, const std::string& intro,
                          const std::vector<std::string>& items) {
  if (items.empty()) return "";
  std::string text = "\n## " + heading + "\n\n" + intro + "\n\n";
  for (const std::string& s : items) text += "- " + s + "\n";
  return text;
}

std::string list_html(const std::string& heading, const std::string& intro,
                      const std::string& css_class, const std::vector<std::string>& items) {
  if (items.empty()) return "";
  std::string o = fmt::format("<h2>{}</h2>\n<p>{}</p>\n<ul class=\"{}\">\n", escape_html(heading),
                              html_with_powers(intro), css_class);
  for (const std::string& s : items) o += "<li>" + html_with_powers(s) + "</li>\n";
  return o + "</ul>\n";
}

}  // namespace

std::vector<std::string> work_model_sentences(const StudyResult& r) {
  std::vector<std::string> out;
  for (const WorkModel& m : r.work_models) out.push_back(work_sentence(m));
  return out;
}

std::vector<std::string> count_claim_sentences(const StudyResult& r) {
  std::vector<std::string> out;
  for (const CountClaim& c : r.count_claims) out.push_back(claim_sentence(r, c));
  return out;
}

std::vector<CountTable> count_tables(const StudyResult& r) {
  std::vector<CountTable> out;
  for (const std::string& scene : r.scenes) {
    std::set<double> columns;
    for (const CountScaling& s : r.count_scaling)
      if (s.scene == scene && s.axis == kPixelsAxis) columns.insert(s.n);
    CountTable t;
    t.scene = scene;
    const std::string axis = r.axes.count(scene) ? r.axes.at(scene) : "N";
    t.header = {"renderer", "count", "against " + axis};
    for (double n : columns) t.header.push_back("against pixels at " + format_number(n));
    // Rows in the order the scaling was computed: renderer by renderer, count by count.
    std::vector<std::pair<std::string, std::string>> keys;
    std::map<std::pair<std::string, std::string>, std::vector<std::string>> cells;
    for (const CountScaling& s : r.count_scaling) {
      if (s.scene != scene) continue;
      const auto key = std::pair{s.renderer, s.counter};
      if (!cells.count(key)) {
        keys.push_back(key);
        cells[key].assign(t.header.size() - 2, "");
      }
      const std::string cell = fmt::format("{:.2f} (R² {:.3f})", s.exponent, s.r2);
      if (s.axis != kPixelsAxis) {
        cells[key][0] = cell;
      } else {
        size_t k = 1;
        for (double n : columns) {
          if (n == s.n) cells[key][k] = cell;
          ++k;
        }
      }
    }
    for (const auto& key : keys) {
      std::vector<std::string> row = {key.first, key.second};
      for (const std::string& c : cells[key]) row.push_back(c.empty() ? "–" : c);
      t.rows.push_back(std::move(row));
    }
    if (!t.rows.empty()) out.push_back(std::move(t));
  }
  return out;
}

std::string counted_work_markdown(const StudyResult& r) {
  std::string text =
      list_markdown("Cost models from counted work", kWorkIntro, work_model_sentences(r));
  text += list_markdown("The chapter's claims, checked on counts", kClaimsIntro,
                        count_claim_sentences(r));
  const std::vector<CountTable> tables = count_tables(r);
  if (!tables.empty()) {
    text += "\n## How the counted work scales\n\n" + std::string(kTablesIntro) + "\n";
    for (const CountTable& t : tables) text += markdown_table(t);
  }
  return text;
}

std::string counted_work_html(const StudyResult& r) {
  std::string o = list_html("Cost models from counted work", kWorkIntro, "work-models",
                            work_model_sentences(r));
  o += list_html("The chapter's claims, checked on counts", kClaimsIntro, "count-claims",
                 count_claim_sentences(r));
  const std::vector<CountTable> tables = count_tables(r);
  if (tables.empty()) return o;
  o += "<h2>How the counted work scales</h2>\n<p>" + html_with_powers(kTablesIntro) + "</p>\n";
  for (const CountTable& t : tables) {
    o += fmt::format("<h3>{}</h3>\n<div class=\"scroll\"><table class=\"count-scaling\"><tr>",
                     escape_html(t.scene));
    for (const std::string& h : t.header) o += "<th>" + escape_html(h) + "</th>";
    o += "</tr>\n";
    for (const auto& row : t.rows) {
      o += "<tr>";
      for (size_t k = 0; k < row.size(); ++k)
        o += (k < 2 ? "<td>" : "<td class=\"num\">") + html_with_powers(row[k]) + "</td>";
      o += "</tr>\n";
    }
    o += "</table></div>\n";
  }
  return o;
}

}  // namespace rvr::study
