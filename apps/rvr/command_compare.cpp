// rvr compare: the compared renderers' images, the difference pictures, metrics.json and
// report.html.
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "report.h"
#include "report_input.h"
#include "rvr/compare/compare.h"
#include "rvr/compare/effect_errors.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/expected.h"
#include "rvr/core/render_option_table.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/compare_renderers.h"
#include "rvr/renderers/registry.h"
#include "terminal_progress.h"

namespace rvr::cli {
namespace {

// The summary of one pair on stdout.
void print_pair(const ReportPair& p, const std::string& name_a, const std::string& name_b) {
  const ComparisonMetrics& m = p.metrics;
  const VisibilityMetrics& v = m.visibility;
  std::printf("  %s vs %s:\n", name_a.c_str(), name_b.c_str());
  std::printf("  id agreement      %.5f  (%zu of %zu pixels differ)\n", v.id_agreement,
              v.mismatched_pixels, v.pixels);
  std::printf("  covered           %.5f of the pixels (%zu), agreement over them %.5f\n",
              v.covered_fraction, v.covered_pixels, v.covered_agreement);
  std::printf("  mismatch classes  edge %zu  depth_precision %zu  occlusion %zu  coverage %zu\n",
              v.classes.edge, v.classes.depth_precision, v.classes.occlusion, v.classes.coverage);
  std::printf("  depth rel error   max %.3g  mean %.3g  p99 %.3g  p99.9 %.3g\n",
              m.depth.max_rel_error, m.depth.mean_rel_error, m.depth.p99_rel_error,
              m.depth.p999_rel_error);
  if (m.depth.outliers)
    std::printf(
        "  depth outliers    %zu above %g: %zu at silhouettes, %zu on analytic spheres, %zu "
        "elsewhere\n",
        m.depth.outliers, kDepthOutlierThreshold, m.depth.outliers_at_silhouettes,
        m.depth.outliers_on_analytic_spheres, m.depth.outliers_elsewhere);
  std::printf("  colour            rmse %.4g  psnr %.2f dB  max %.4g  ssim %.4f\n", m.colour.rmse,
              m.colour.psnr_db, m.colour.max_abs, m.colour.ssim);
  if (m.lod.pixels > 0)
    std::printf("  texture lod       |a - b| mean %.3g  p99 %.3g levels over %zu pixels\n",
                m.lod.mean_abs, m.lod.p99_abs, m.lod.pixels);
  for (const EffectError& e : m.effects) {
    std::printf(
        "  %-17s rmse %.4g  psnr %.2f dB  max %.4g  ssim %.4f  over %zu pixels (%s's mask)\n",
        e.effect.c_str(), e.rmse, e.psnr_db, e.max_abs, e.ssim, e.pixels,
        m.effects_mask_from.c_str());
    for (const AnswerError& s : e.answers)
      std::printf("    %-21s psnr %.2f dB  max %.4g  ssim %.4f  over %zu pixels (%s's answer)\n",
                  s.answer.c_str(), s.psnr_db, s.max_abs, s.ssim, s.pixels, m.answers_from.c_str());
  }
}

// The exit status the thresholds give: 1 when a pair's id agreement is below
// --fail-below-agreement or it has nothing visible, or a pair has a mismatch of a --fail-on class.
int verdict(const CompareArgs& a, const std::vector<ReportPair>& pairs,
            const std::vector<std::string>& keys) {
  int status = 0;
  for (const ReportPair& p : pairs) {
    const VisibilityMetrics& v = p.metrics.visibility;
    const std::string pair = keys[p.a] + " vs " + keys[p.b];
    if (a.fail_below_agreement && v.covered_pixels == 0) {
      std::fprintf(stderr, "%s: nothing visible in either image: no agreement to measure\n",
                   pair.c_str());
      status = 1;
    } else if (a.fail_below_agreement && v.id_agreement < *a.fail_below_agreement) {
      std::fprintf(stderr, "%s: id agreement %.5f is below %.5f\n", pair.c_str(), v.id_agreement,
                   *a.fail_below_agreement);
      status = 1;
    }
    for (const std::string& name : a.fail_on) {
      const std::optional<MismatchClass> c = parse_mismatch_class(name);  // checked by CLI11
      if (!c || v.classes.of(*c) == 0) continue;
      std::fprintf(stderr, "%s: %zu %s mismatches\n", pair.c_str(), v.classes.of(*c), name.c_str());
      status = 1;
    }
  }
  return status;
}

}  // namespace

int run_compare(const CompareArgs& a, const std::string& command_line) {
  if (a.renderers.size() < 2)
    fail(bad_input("--renderers: need at least two renderers to compare"));
  refuse_overwriting_inputs({a.common.scene},
                            {a.out_dir + "/metrics.json", a.out_dir + "/report.html"});
  TerminalProgress progress(progress_wanted(a.common.quiet));
  progress.begin("", "load");
  RenderOptions options = render_options(a.common, "local");
  double load_seconds = 0;
  Scene scene = load(a.common, options, load_seconds);
  options.progress = progress.sink();

  CompareOptions compare;
  compare.config.gl = gl_backend(a.common);
  compare.on_phase = [&](const std::string& label, const std::string& phase) {
    progress.begin(label, phase);
  };
  // Everything is computed before the first file is written.
  CompareResult result = take(compare_renderers(scene, a.renderers, options, compare));
  const std::vector<std::string> given = given_render_options(a.common);
  for (size_t i = 0; i < result.renderers.size(); ++i)
    for (std::string& w : unread_option_warnings(given, a.renderers[i], true))
      result.renderers[i].output.warnings.push_back(std::move(w));

  ReportContext context;
  context.mode = to_string(options.mode);
  context.load_seconds = load_seconds;
  context.command_line = command_line;
  context.out_dir = a.out_dir;
  const ReportInput report = report_input(scene, result, compare, context);
  const std::vector<std::string> keys = renderer_keys(a.renderers);

  for (size_t i = 0; i < result.renderers.size(); ++i) {
    check(write_image(a.out_dir + "/" + report.renderers[i].image_file, result.renderers[i].image));
    if (!report.renderers[i].cost_file.empty())
      check(write_image(a.out_dir + "/" + report.renderers[i].cost_file,
                        result.renderers[i].cost_image, false));
  }
  for (size_t k = 0; k < result.pairs.size(); ++k) {
    const ComparedPair& p = result.pairs[k];
    const ReportPair& rp = report.pairs[k];
    check(write_image(a.out_dir + "/" + rp.file("diff"), p.diff, false));
    check(write_image(a.out_dir + "/" + rp.file("id_mismatch"), p.id_mismatch, false));
    check(write_image(a.out_dir + "/" + rp.file("depth_diff"), p.depth_diff, false));
    check(write_image(a.out_dir + "/" + rp.file("mismatch_classes"), p.mismatch_classes, false));
    if (!p.metrics.effects.empty())
      check(write_image(a.out_dir + "/" + rp.file("effects"), p.effects, false));
    if (!p.metrics.answers_from.empty())
      check(write_image(a.out_dir + "/" + rp.file("answers"), p.answers, false));
  }
  check(write_text_file(a.out_dir + "/metrics.json", metrics_json(report)));
  check(write_text_file(a.out_dir + "/report.html", take(report_html(report))));

  progress.stop();  // before the warnings and the table
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  for (const ReportRenderer& r : report.renderers)
    for (const std::string& w : r.warnings)
      std::fprintf(stderr, "warning: %s: %s\n", r.name.c_str(), w.c_str());
  for (const std::string& w : result.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  std::printf("%s  %dx%d  mode %s\n", scene.source.c_str(), scene.image.width, scene.image.height,
              report.mode.c_str());
  for (const ReportRenderer& r : report.renderers)
    std::printf("  %-12s %9.3f s  depth %s\n", r.name.c_str(), r.seconds, r.depth_format.c_str());
  for (const ReportPair& p : report.pairs) print_pair(p, keys[p.a], keys[p.b]);
  // Every file written, in the order written.
  std::printf("  wrote %s/{", a.out_dir.c_str());
  for (const ReportRenderer& r : report.renderers) {
    std::printf("%s,", r.image_file.c_str());
    if (!r.cost_file.empty()) std::printf("%s,", r.cost_file.c_str());
  }
  for (const ReportPair& p : report.pairs) {
    std::printf("%s,%s,%s,%s,", p.file("diff").c_str(), p.file("depth_diff").c_str(),
                p.file("id_mismatch").c_str(), p.file("mismatch_classes").c_str());
    if (!p.metrics.effects.empty()) std::printf("%s,", p.file("effects").c_str());
    if (!p.metrics.answers_from.empty()) std::printf("%s,", p.file("answers").c_str());
  }
  std::printf("metrics.json,report.html}\n");
  return verdict(a, report.pairs, keys);
}

}  // namespace rvr::cli
