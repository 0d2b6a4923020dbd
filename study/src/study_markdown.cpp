// study.md (see study_markdown.h).
#include "rvr/study/study_markdown.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "counted_work_text.h"
#include "rvr/study/bootstrap.h"
#include "rvr/study/conclusions.h"
#include "rvr/study/cost_model.h"
#include "rvr/study/measurement.h"
#include "rvr/study/memory_estimate.h"
#include "rvr/study/scene_changes.h"
#include "rvr/study/system_probe.h"

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

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

// The sentences of one section, as a Markdown list under its heading; nothing when empty.
std::string section(const std::string& heading, const std::string& intro,
                    const std::vector<std::string>& sentences) {
  if (sentences.empty()) return "";
  std::string text = "\n## " + heading + "\n\n" + (intro.empty() ? "" : intro + "\n\n");
  for (const std::string& s : sentences) text += "- " + s + "\n";
  return text;
}

std::string header(const StudyResult& r) {
  std::string text = "# rvr study\n\n";
  text += "**Scope.** " + scope_text(r) + "\n\n";
  text += "**Method.** " + method_text(r) + "\n\n";
  // A study run without the CLI (Python, tests) may not know the processor.
  const std::string cpu = r.machine.cpu.empty() ? "processor not recorded" : r.machine.cpu;
  const std::string threads =
      r.machine.threads > 0 ? fmt::format(", {} threads", r.machine.threads) : "";
  const std::string kernels =
      r.machine.kernels.empty() ? "" : fmt::format("; kernels: {}", r.machine.kernels);
  text += fmt::format("**Machine.** {}{}{}. Before the sweep: {}; after: {}.\n", cpu, threads,
                      kernels, describe(r.system_before), describe(r.system_after));
  if (!r.no_conclusion.empty()) text += "\n## No conclusion\n\n" + r.no_conclusion + ".\n";
  return text;
}

std::vector<std::string> scaling_sentences(const StudyResult& r) {
  std::vector<std::string> out;
  for (const ScalingExponent& s : r.scaling)
    out.push_back(
        s.axis == kPixelsAxis
            ? fmt::format("{} on {} with {} {}: time grows as P^{:.2f} from {} to {} pixels.",
                          s.renderer, s.scene, format_number(s.n), r.axes.at(s.scene), s.exponent,
                          format_number(s.from), format_number(s.to))
            : fmt::format("{} on {}: time grows as N^{:.2f} from {} to {}.", s.renderer, s.scene,
                          s.exponent, format_number(s.from), format_number(s.to)));
  return out;
}

std::vector<std::string> cost_sentences(const StudyResult& r) {
  std::vector<std::string> out;
  for (const UnitCost& c : r.costs)
    out.push_back(fmt::format(
        "{} on {} at {} {}: {} ms a frame, {} ns per triangle, {} ns per ray.", c.renderer, c.scene,
        format_number(c.n), r.axes.at(c.scene), format_number(1e3 * c.seconds),
        format_number(c.ns_per_triangle), format_number(c.ns_per_ray)));
  return out;
}

std::vector<std::string> split_sentences(const StudyResult& r) {
  std::vector<std::string> out;
  for (const PhaseSplit& s : r.splits)
    out.push_back(fmt::format(
        "{} on {} at {} {}: z-buffer pass {} ms, the tracer's part {} ms ({:.0f}% z-buffer).",
        s.renderer, s.scene, format_number(s.n), r.axes.at(s.scene),
        format_number(1e3 * s.zbuffer_seconds), format_number(1e3 * s.trace_seconds),
        100 * s.zbuffer_share));
  return out;
}

// In full mode the loop orders do not render the same frame: what each renderer of the study
// renders there. "" in the other modes, where they do.
std::string full_mode_text(const StudyResult& r) {
  if (r.mode != "full") return "";
  std::vector<std::string> each;
  for (const std::string& name : r.renderers) {
    switch (model_form_of(name)) {
      case ModelForm::ZBuffer:
        each.push_back(name +
                       " shadow maps (a cube of six per light sample, drawn over every "
                       "triangle), a view drawn again per flat mirror and ior-1 layer seen and a "
                       "cube map of six views per curved mirror or other transparent object: "
                       "every triangle drawn once more per such view, where a tracer casts a ray "
                       "per pixel of the effect (each technique's error against raytrace at "
                       "each point: 'Each technique's error' below, when the study holds "
                       "raytrace; each technique's cost: bench/charts/effects.md)");
        break;
      case ModelForm::Tracer:
        each.push_back(name + " shadow rays and reflection and refraction rays");
        break;
      case ModelForm::Hybrid:
        each.push_back(name +
                       " its z-buffer's visibility pass, then the tracer's shadow, reflection "
                       "and refraction rays");
        break;
    }
  }
  return " What each renderer renders in full mode: " + join(each) + ".";
}

}  // namespace

std::string scope_text(const StudyResult& r) {
  const char* mode = r.mode == "visibility" ? "ids and depth only, no shading"
                     : r.mode == "local"    ? "the shading equation, no shadows or reflections"
                                            : "shadows, reflections and every effect each renderer "
                                              "renders";
  return fmt::format(
      "{} at {}×{} in {} mode ({}).{} Frame times of static scenes: what a renderer builds per "
      "scene (the tracers' and the hybrids' BVH) is timed apart from its frames, and the frames "
      "a scene must last to pay for it are given with it; the z-buffers build nothing per "
      "scene. One machine type ({}).",
      join(r.scenes), r.width, r.height, r.mode, mode, full_mode_text(r),
      r.machine.cpu.empty() ? "unnamed" : r.machine.cpu);
}

std::string method_text(const StudyResult& r) {
  size_t processes = 0;
  for (const SessionInfo& s : r.sessions) processes += s.kind == "process";
  const std::string sessions =
      processes == r.sessions.size() ? "fresh processes" : "fresh preparations of the scene";
  return fmt::format(
      "Each point was measured in {} sessions ({}), {} rounds each, the renderers in a random "
      "order in every round; ratios are paired round by round. A renderer is called faster only "
      "beyond a {:.0f}% noise threshold, judged at each point on the trend through it and its "
      "nearest neighbours, Holm-corrected over the points of a sweep ({:.0f}% family-wise); a "
      "crossover needs two consecutive such points on each side. Intervals: a hierarchical "
      "bootstrap ({} replicates: sessions, then rounds) with the scatter between neighbouring "
      "points. {:.0f} s of measuring of a {:.0f} s budget.",
      r.sessions_per_point, sessions, r.repetitions, 100 * r.noise_threshold, 100 * kFamilyAlpha,
      r.bootstrap_replicates, r.elapsed_seconds, r.budget_seconds);
}

std::string crossover_sentence(const StudyResult& r, const Crossover& c) {
  const std::string& below = c.a_faster_below ? c.a : c.b;
  const std::string& above = c.a_faster_below ? c.b : c.a;
  std::string where = where_text(r, c.scene, c.axis, c.n);
  const std::string demoted =
      c.contradicted ? " A prediction check contradicts it: it is not confirmed." : "";
  if (!c.measured)
    return fmt::format(
        "{}, the fitted models put the crossover of {} and {} at {} {}, outside the swept "
        "range {} (extrapolated, not measured): {} is faster below it, {} above.{}",
        where, c.a, c.b, format_number(c.value), c.axis,
        range_text(c.range_low, c.range_high, c.axis), below, above, demoted);
  return fmt::format(
      "{}, {} is faster than {} below {} {} {}; {} is faster above (significantly at {} points "
      "below, by {:.2f}× at the nearest, and {} above, by {:.2f}×).{}",
      where, below, above, format_number(c.value), c.axis, interval_text(c), above, c.below_points,
      c.below_ratio, c.above_points, c.above_ratio, demoted);
}

std::string dominance_sentence(const StudyResult& r, const Dominance& d) {
  std::string text = fmt::format(
      "{}, {} is faster than {} where significant: at {} of {} points ({}), by at least {:.2f}× "
      "(at {} {})",
      where_text(r, d.scene, d.axis, d.n), d.faster, d.slower, d.significant, d.points,
      range_text(d.significant_low, d.significant_high, d.axis), d.min_ratio, format_number(d.at),
      d.axis);
  text += d.significant < d.points
              ? fmt::format("; at the others the two are within the {:.0f}% noise threshold",
                            100 * r.noise_threshold)
              : "";
  if (!d.contrary.empty()) {
    std::vector<std::string> at;
    for (size_t k = 0; k < d.contrary.size() && k < 6; ++k)
      at.push_back(fmt::format("{} ({:.2f}×)", format_number(d.contrary[k]), d.contrary_ratios[k]));
    if (d.contrary.size() > 6) at.push_back(fmt::format("{} more", d.contrary.size() - 6));
    text += fmt::format(". {} measured faster at {} {}", d.slower, join(at), d.axis);
  }
  return text + ".";
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
  std::string where;
  if (c.extrapolated && std::fabs(std::log(c.at / c.crossover)) < std::log(1.5))
    where = fmt::format("at the extrapolated crossover {}", format_number(c.crossover));
  else
    where = fmt::format("{} the {}crossover at {}", c.at < c.crossover ? "below" : "above",
                        c.extrapolated ? "extrapolated " : "", format_number(c.crossover));
  const std::string expected = c.predicted_faster.empty()
                                   ? "the two should be about equal"
                                   : c.predicted_faster + " should be faster";
  const std::string model =
      std::isfinite(c.predicted_ratio)
          ? fmt::format(", the models predicted {:.2f} (95%: {:.2f} – {:.2f})", c.predicted_ratio,
                        c.predicted_ci95.low, c.predicted_ci95.high)
          : "";
  return fmt::format(
      "on {} at {} {} ({}), {}: measured t({}) / t({}) = {:.2f} (95%: {:.2f} – {:.2f}){}. "
      "{}: {}.",
      c.scene, format_number(c.at), c.axis, where, expected, c.a, c.b, c.ratio, c.ratio_ci95.low,
      c.ratio_ci95.high, model,
      c.verdict == "holds"   ? "Holds"
      : c.verdict == "fails" ? "Fails"
                             : "Inconclusive",
      c.why);
}

std::vector<std::string> headline_sentences(const StudyResult& r) {
  std::vector<std::string> out;
  auto order = [](const std::string& name) { return model_form_of(name); };
  auto loop_pair = [&](const std::string& a, const std::string& b) {
    return (order(a) == ModelForm::ZBuffer && order(b) == ModelForm::Tracer) ||
           (order(a) == ModelForm::Tracer && order(b) == ModelForm::ZBuffer);
  };
  for (const std::string& scene : r.scenes)
    for (const Comparison& x : r.comparisons) {
      if (x.scene != scene || x.axis == kPixelsAxis || !loop_pair(x.a, x.b)) continue;
      std::vector<std::string> found;
      for (const Crossover& c : r.crossovers)
        if (c.scene == scene && c.a == x.a && c.b == x.b && c.axis == x.axis)
          found.push_back(crossover_sentence(r, c));
      for (const Dominance& d : r.dominance)
        if (d.scene == scene && d.axis == x.axis &&
            ((d.faster == x.a && d.slower == x.b) || (d.faster == x.b && d.slower == x.a)))
          found.push_back(dominance_sentence(r, d));
      if (found.empty())
        found.push_back(x.inconclusive.empty()
                            ? fmt::format("{} on {}: {} and {} are within the noise threshold at "
                                          "every point measured.",
                                          x.axis, scene, x.a, x.b)
                            : fmt::format("{} on {}: nothing is concluded for {} and {}: {}.",
                                          x.axis, scene, x.a, x.b, x.inconclusive));
      for (const std::string& s : found) out.push_back(s);
    }
  return out;
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

std::vector<std::string> technique_error_sentences(const StudyResult& r) {
  struct Range {
    double worst_psnr = std::numeric_limits<double>::infinity(), best_psnr = -1;
    double worst_ssim = 1, best_ssim = -1, min_pixels = 0, max_pixels = 0;
    const Measurement* worst = nullptr;
    size_t points = 0;
  };
  // In the study's orders of renderers and families, effects in effect_errors' order.
  const std::vector<std::string> effect_order = {"reflection", "refraction", "lens", "csg"};
  std::map<std::tuple<size_t, size_t, size_t>, Range> ranges;
  for (const Measurement& m : r.points) {
    const size_t renderer =
        size_t(std::find(r.renderers.begin(), r.renderers.end(), m.renderer) - r.renderers.begin());
    const size_t scene =
        size_t(std::find(r.scenes.begin(), r.scenes.end(), m.scene) - r.scenes.begin());
    for (const PointEffectError& e : m.effect_errors) {
      const size_t effect = size_t(std::find(effect_order.begin(), effect_order.end(), e.effect) -
                                   effect_order.begin());
      Range& g = ranges[{renderer, scene, effect}];
      if (g.points == 0 || e.psnr_db < g.worst_psnr) {
        g.worst_psnr = e.psnr_db;
        g.worst = &m;
      }
      g.best_psnr = std::max(g.best_psnr, e.psnr_db);
      g.worst_ssim = std::min(g.worst_ssim, e.ssim);
      g.best_ssim = std::max(g.best_ssim, e.ssim);
      g.min_pixels = g.points == 0 ? e.pixels : std::min(g.min_pixels, e.pixels);
      g.max_pixels = std::max(g.max_pixels, e.pixels);
      ++g.points;
    }
  }
  auto span = [](double lo, double hi) {
    return lo == hi ? format_number(lo) : format_number(lo) + " to " + format_number(hi);
  };
  std::vector<std::string> out;
  for (const auto& [key, g] : ranges) {
    const auto& [renderer, scene, effect] = key;
    out.push_back(fmt::format(
        "{} on {}, {}: PSNR {} dB, SSIM {} in a mask of {} pixels, over {} point{}; worst at {} "
        "{}, {}×{}.",
        r.renderers.at(renderer), r.scenes.at(scene),
        effect < effect_order.size() ? effect_order[effect] : "other",
        span(g.worst_psnr, g.best_psnr), span(g.worst_ssim, g.best_ssim),
        span(g.min_pixels, g.max_pixels), g.points, g.points == 1 ? "" : "s",
        format_number(g.worst->n), r.axes.at(g.worst->scene), g.worst->width, g.worst->height));
  }
  return out;
}

std::string study_markdown(const StudyResult& r) {
  std::string text = header(r);
  text += section("Where the pixel-major loop overtakes the triangle-major one",
                  "The chapter's question: the z-buffer against the tracer along N.",
                  headline_sentences(r));
  std::vector<std::string> crossovers, dominance, checks, models, notes;
  for (const Crossover& c : r.crossovers) crossovers.push_back(crossover_sentence(r, c));
  for (const Dominance& d : r.dominance) dominance.push_back(dominance_sentence(r, d));
  for (const PredictionCheck& c : r.checks) checks.push_back(check_sentence(c));
  for (const RendererModels& m : r.models)
    for (const auto& [scene, f] : m.fits) models.push_back(model_sentence(m, scene, f));
  for (const std::string& note : r.notes) notes.push_back(note + ".");
  text += section("Crossovers", "", crossovers);
  text += section("Faster where significant", "", dominance);
  text += section("Predictions checked",
                  "Each crossover checked out of sample after the fit: points off the sweep's "
                  "grid, measured in fresh sessions.",
                  checks);
  text += section("The hybrids' split", "", split_sentences(r));
  text += section("Each technique's error",
                  "Full mode: each renderer's frame of every point against raytrace's, in the "
                  "mask of the pixels each effect touches (read from the tracer's ray tree, as "
                  "rvr compare's by_effect). The error is exact, not sampled: the same in every "
                  "run.",
                  technique_error_sentences(r));
  text += section("Building per scene",
                  "What each renderer builds before its first frame, timed in every run; a scene "
                  "that changes every k frames costs t_frame + t_prepare / k a frame.",
                  build_sentences(r));
  std::vector<std::string> memory;
  for (const FamilyMemory& m : r.memory)
    if (std::string s = memory_sentence(m); !s.empty()) memory.push_back(s);
  text += section("Memory",
                  "Estimated before a family's sweep went past 10^6 triangles; planned N that "
                  "would not fit were dropped (see the notes).",
                  memory);
  text += section("Cost models", "", models);
  text += counted_work_markdown(r);
  text += section("Scaling (log-log slope per decade)", "", scaling_sentences(r));
  text += section("Cost per triangle and per ray", "", cost_sentences(r));
  text += section("Notes", "", notes);
  return text;
}

}  // namespace rvr::study
