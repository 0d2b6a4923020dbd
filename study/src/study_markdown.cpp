// study.md (see study_markdown.h).
#include "rvr/study/study_markdown.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <vector>

#include "rvr/study/bootstrap.h"

namespace rvr::study {
namespace {

std::string range_text(double lo, double hi, const std::string& axis) {
  return fmt::format("{}–{} {}", format_number(lo), format_number(hi), axis);
}

// "(95%: 1.7×10^6–2.6×10^6)", with open ends said in words.
std::string interval_text(const Crossover& c) {
  if (std::isnan(c.ci95.low) || std::isnan(c.ci95.high)) return "(no interval: extrapolated)";
  std::string lo = std::isinf(c.ci95.low) ? "below the swept range" : format_number(c.ci95.low);
  std::string hi = std::isinf(c.ci95.high) ? "above the swept range" : format_number(c.ci95.high);
  return fmt::format("(95%: {} – {})", lo, hi);
}

// "at 1024×768 on tessphere", or on the pixels axis "on tessphere with 1.0×10^6 triangles".
std::string where_text(const StudyResult& r, const std::string& scene, const std::string& axis,
                       double n) {
  if (axis == kPixelsAxis)
    return fmt::format("on {} with {} {}", scene, format_number(n), r.axes.at(scene));
  return fmt::format("at {}×{} on {}", r.width, r.height, scene);
}

std::string header(const StudyResult& r) {
  std::string scenes;
  for (const std::string& s : r.scenes) scenes += (scenes.empty() ? "" : ", ") + s;
  std::string text = "# rvr study\n\n";
  text += fmt::format(
      "{} at {}×{}, {} mode; {} repetitions per point, interleaved in random "
      "order; Harrell–Davis medians; 95% intervals from {} bootstrap replicates over the "
      "repetitions. {:.0f} s of a {:.0f} s budget.\n\n",
      scenes, r.width, r.height, r.mode, r.repetitions, r.bootstrap_replicates, r.elapsed_seconds,
      r.budget_seconds);
  text += fmt::format("Machine: {}, {} threads; kernels: {}.\n", r.machine.cpu, r.machine.threads,
                      r.machine.kernels);
  for (const std::string& note : r.notes) text += "\nNote: " + note + ".\n";
  return text;
}

std::string scaling_section(const StudyResult& r) {
  std::string text = "\n## Scaling (log-log slope per decade)\n\n";
  for (const ScalingExponent& s : r.scaling)
    text +=
        s.axis == kPixelsAxis
            ? fmt::format("- {} on {} with {} {}: time grows as P^{:.2f} from {} to {} pixels.\n",
                          s.renderer, s.scene, format_number(s.n), r.axes.at(s.scene), s.exponent,
                          format_number(s.from), format_number(s.to))
            : fmt::format("- {} on {}: time grows as N^{:.2f} from {} to {}.\n", s.renderer,
                          s.scene, s.exponent, format_number(s.from), format_number(s.to));
  text += "\n## Cost per triangle and per ray\n\n";
  for (const UnitCost& c : r.costs)
    text += fmt::format("- {} on {} at {} {}: {} ms a frame, {} ns per triangle, {} ns per ray.\n",
                        c.renderer, c.scene, format_number(c.n), r.axes.at(c.scene),
                        format_number(1e3 * c.seconds), format_number(c.ns_per_triangle),
                        format_number(c.ns_per_ray));
  return text;
}

}  // namespace

std::string crossover_sentence(const StudyResult& r, const Crossover& c) {
  const std::string& below = c.a_faster_below ? c.a : c.b;
  const std::string& above = c.a_faster_below ? c.b : c.a;
  std::string where = where_text(r, c.scene, c.axis, c.n);
  if (!c.measured)
    return fmt::format(
        "{}, the fitted models put the crossover of {} and {} at {} {}, outside the swept "
        "range {} (extrapolated, not measured): {} is faster below it, {} above.",
        where, c.a, c.b, format_number(c.value), c.axis,
        range_text(c.range_low, c.range_high, c.axis), below, above);
  return fmt::format("{}, {} is faster than {} below {} {} {}; {} is faster above.", where, below,
                     above, format_number(c.value), c.axis, interval_text(c), above);
}

std::string dominance_sentence(const StudyResult& r, const Dominance& d) {
  return fmt::format(
      "{}, {} is faster than {} over the whole swept range {}, by at least {:.2f}× (at {} {}).",
      where_text(r, d.scene, d.axis, d.n), d.faster, d.slower,
      range_text(d.range_low, d.range_high, d.axis), d.min_ratio, format_number(d.at), d.axis);
}

std::string coefficient_text(const Coefficient& c) {
  if (!c.identifiable) return "";
  bool seconds = c.name == "a";
  double f = seconds ? 1e3 : 1e9;
  return fmt::format("{} = {} {} (95%: {} – {})", c.name, format_number(c.value * f),
                     seconds ? "ms" : "ns", format_number(c.ci95.low * f),
                     format_number(c.ci95.high * f));
}

std::string model_sentence(const RendererModels& m, const std::string& scene, const ModelFit& f) {
  if (!f.fits)
    return fmt::format("{} on {}: the model {} {}; no conclusion is drawn from it.", m.name, scene,
                       f.formula, f.verdict);
  std::string terms;
  for (const Coefficient& c : f.coefficients)
    if (c.identifiable) terms += (terms.empty() ? "" : ", ") + coefficient_text(c);
  std::string folded = f.fixed_pixels > 0 ? " (one image size: a includes b·P)" : "";
  return fmt::format(
      "{} on {}: {} with {}{}; R² {:.3f}, largest residual {:.0f}%, leave-one-out error "
      "{:.0f}% (median); {}.",
      m.name, scene, f.formula, terms, folded, f.r2, 100 * f.max_rel_residual,
      100 * f.loo_rel_error, f.selection);
}

std::string check_sentence(const PredictionCheck& c) {
  const std::string& other = c.predicted_faster == c.a ? c.b : c.a;
  return fmt::format(
      "on {} at {} {} ({} the crossover at {}), {} should be faster than {}: {}, {:.2f}×{}.",
      c.scene, format_number(c.at), c.axis, c.at < c.crossover ? "below" : "above",
      format_number(c.crossover), c.predicted_faster, other, c.holds ? "it is" : "it is not",
      c.ratio,
      c.holds ? ""
              : fmt::format(" the other way ({} is faster): the prediction does not hold",
                            c.measured_faster));
}

std::string format_number(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "n/a" : (v > 0 ? "∞" : "−∞");
  double a = std::fabs(v);
  if (a >= 99.95 && a < 1e4) return fmt::format("{:.0f}", v);
  if (a == 0 || (a >= 0.01 && a < 1e4)) return fmt::format("{:.3g}", v);
  int e = int(std::floor(std::log10(a)));
  double m = v / std::pow(10.0, e);
  if (std::fabs(m) >= 9.95) m /= 10, ++e;  // 9.97 would print as 10.0
  return fmt::format("{:.1f}×10^{}", m, e);
}

std::string study_markdown(const StudyResult& r) {
  std::string text = header(r);
  text += "\n## Crossovers\n\n";
  for (const Crossover& c : r.crossovers) text += "- " + crossover_sentence(r, c) + "\n";
  for (const Dominance& d : r.dominance) text += "- " + dominance_sentence(r, d) + "\n";
  if (r.crossovers.empty() && r.dominance.empty()) text += "No pair of loop orders was measured.\n";
  if (!r.checks.empty()) {
    text +=
        "\n## Predictions checked\n\nEach crossover measured again after the fit, at a third of "
        "and three times its value:\n\n";
    for (const PredictionCheck& c : r.checks) text += "- " + check_sentence(c) + "\n";
  }
  if (!r.splits.empty()) {
    text += "\n## The hybrids' split\n\n";
    for (const PhaseSplit& s : r.splits)
      text += fmt::format(
          "- {} on {} at {} {}: z-buffer pass {} ms, the tracer's part {} ms ({:.0f}% z-buffer).\n",
          s.renderer, s.scene, format_number(s.n), r.axes.at(s.scene),
          format_number(1e3 * s.zbuffer_seconds), format_number(1e3 * s.trace_seconds),
          100 * s.zbuffer_share);
  }
  text += "\n## Cost models\n\n";
  for (const RendererModels& m : r.models)
    for (const auto& [scene, f] : m.fits) text += "- " + model_sentence(m, scene, f) + "\n";
  text += scaling_section(r);
  return text;
}

}  // namespace rvr::study
