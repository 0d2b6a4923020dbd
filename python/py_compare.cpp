// rvr.compare and rvr.diff: `rvr compare`'s metrics.json for two renders, `rvr diff` for two
// image files, through the libraries the command line uses.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // IWYU pragma: keep (type casters for std containers)

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "bindings.h"
#include "errors.h"
#include "py_render.h"
#include "render_stats.h"
#include "report.h"
#include "report_input.h"
#include "rvr/renderers/compare_renderers.h"
#include "rvr/shared/compare.h"
#include "rvr/shared/framebuffers.h"
#include "rvr/shared/image_io.h"
#include "rvr/shared/renderer.h"

namespace py = pybind11;

namespace rvr::python {
namespace {

ComparedRenderer compared(const RenderResult& r) {
  ComparedRenderer c;
  c.name = r.renderer;
  c.seconds = r.times.render;
  c.output = r.output;
  return c;
}

py::object compare(const PyRender& a, const PyRender& b) {
  const RenderResult& ra = *a.result;
  const RenderResult& rb = *b.result;
  const FrameBuffers& fa = ra.output.buffers;
  const FrameBuffers& fb = rb.output.buffers;
  if (fa.width != fb.width || fa.height != fb.height)
    throw BadInputError("compare: the renders differ in size: " + std::to_string(fa.width) + "x" +
                        std::to_string(fa.height) + " and " + std::to_string(fb.width) + "x" +
                        std::to_string(fb.height));
  CompareOptions options;
  CompareResult result = compare_rendered(*ra.scene, {compared(ra), compared(rb)}, options);
  ReportContext context;
  context.mode = to_string(ra.mode);
  context.load_seconds = ra.times.load;
  context.command_line = "rvr.compare(" + ra.renderer + ", " + rb.renderer + ")";
  const ReportInput report = report_input(*ra.scene, result, options, context);
  return py::module_::import("json").attr("loads")(metrics_json(report));
}

py::dict diff(const std::string& path_a, const std::string& path_b, float fail, float fail_percent,
              std::optional<float> hard_fail, float warn, float warn_percent,
              std::optional<float> hard_warn, std::optional<double> fail_above,
              const std::string& out) {
  DiffThresholds t;
  t.fail = fail;
  t.fail_percent = fail_percent;
  if (hard_fail) t.hard_fail = *hard_fail;
  t.warn = warn;
  t.warn_percent = warn_percent;
  if (hard_warn) t.hard_warn = *hard_warn;
  Image a = take(read_image(path_a));
  Image b = take(read_image(path_b));
  ImageDiff d = take(diff_images(a, b, t));
  if (!out.empty()) check(write_image(out, diff_heat_map(a, b, 0.1f), false));
  DiffVerdict verdict = diff_verdict(d, t);
  if (fail_above && d.rmse > *fail_above) verdict = DiffVerdict::Failure;
  py::dict r;
  r["mean_error"] = d.mean_abs;
  r["rms_error"] = d.rmse;
  r["peak_snr"] = d.psnr_db;
  r["max_error"] = d.max_abs;
  r["max_at"] = py::make_tuple(d.max_x, d.max_y, d.max_channel);
  r["pixels"] = d.pixels;
  r["warn_pixels"] = d.warn_pixels;
  r["fail_pixels"] = d.fail_pixels;
  r["verdict"] = to_string(verdict);
  return r;
}

}  // namespace

void bind_compare(py::module_& m) {
  m.def("compare", &compare, py::arg("a"), py::arg("b"),
        "Compares two renders of one scene (A the reference) as `rvr compare` does: a dict "
        "with the keys and values of metrics.json (docs/cli.md), through the same writer.");
  const DiffThresholds defaults;
  m.def("diff", &diff, py::arg("path_a"), py::arg("path_b"), py::kw_only(),
        py::arg("fail") = defaults.fail, py::arg("fail_percent") = defaults.fail_percent,
        py::arg("hard_fail") = py::none(), py::arg("warn") = defaults.warn,
        py::arg("warn_percent") = defaults.warn_percent, py::arg("hard_warn") = py::none(),
        py::arg("fail_above") = py::none(), py::arg("out") = "",
        "Compares two image files as `rvr diff` does (idiff's thresholds; fail_above: FAILURE "
        "when the RMS error is above it; out: a heat map file). A dict: mean_error, rms_error, "
        "peak_snr, max_error, max_at (x, y, channel), pixels, warn_pixels, fail_pixels, "
        "verdict (PASS, WARNING, FAILURE).");
}

}  // namespace rvr::python
