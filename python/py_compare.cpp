// rvr.compare and rvr.diff: `rvr compare`'s metrics.json for two renders of one scene, `rvr diff`
// for two images (files, arrays or renders), through the libraries the command line uses.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // IWYU pragma: keep (type casters for std containers)

#include <algorithm>
#include <array>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arguments.h"
#include "bindings.h"
#include "errors.h"
#include "py_render.h"
#include "render_stats.h"
#include "report.h"
#include "report_input.h"
#include "rvr/compare/compare.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes.h"
#include "rvr/core/texture.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/compare_renderers.h"
#include "stub_docs.h"

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

bool same_camera(const Camera& a, const Camera& b) {
  return a.eye == b.eye && a.target == b.target && a.up == b.up && a.fov_y_deg == b.fov_y_deg &&
         a.near == b.near && a.far == b.far && a.aperture_radius == b.aperture_radius &&
         a.focus_distance == b.focus_distance;
}

bool same_image(const ImageSettings& a, const ImageSettings& b) {
  return a.width == b.width && a.height == b.height && a.background == b.background &&
         a.samples_per_pixel == b.samples_per_pixel && a.exposure == b.exposure;
}

bool same_material(const Material& a, const Material& b) {
  return a.diffuse == b.diffuse && a.specular == b.specular && a.emission == b.emission &&
         a.shininess == b.shininess && a.mirror == b.mirror && a.transparency == b.transparency &&
         a.ior == b.ior && a.texture == b.texture &&
         a.uv_transform.offset == b.uv_transform.offset &&
         a.uv_transform.rotation == b.uv_transform.rotation &&
         a.uv_transform.scale == b.uv_transform.scale;
}

bool same_light(const Light& a, const Light& b) {
  return a.type == b.type && a.position == b.position && a.corner == b.corner &&
         a.edge_u == b.edge_u && a.edge_v == b.edge_v && a.intensity == b.intensity &&
         a.samples == b.samples;
}

bool same_object(const Object& a, const Object& b) {
  if (a.type != b.type || a.material != b.material) return false;
  // Shape by shape (a CSG solid by its tree, which is not edited after loading: shared when the
  // same).
  return visit_shape(a, [&](const auto& shape_a) {
    return visit_shape(b, [&](const auto& shape_b) {
      if constexpr (std::is_same_v<decltype(shape_a), decltype(shape_b)>) return shape_a == shape_b;
      return false;
    });
  });
}

template <class T, class Same>
bool same_all(const std::vector<T>& a, const std::vector<T>& b, Same&& same) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), same);
}

bool same_texture(const Texture& a, const Texture& b) {
  return a.resolved == b.resolved && a.file == b.file && a.wrap_u == b.wrap_u &&
         a.wrap_v == b.wrap_v && (a.mips == nullptr) == (b.mips == nullptr);
}

// What makes the renders of `a` and `b` not renders of one scene as `rvr compare` makes them
// (one scene, one camera, one mode); empty when nothing does.
std::string difference(const RenderResult& a, const RenderResult& b) {
  if (a.mode != b.mode)
    return std::string("the renders differ in mode: ") + to_string(a.mode) + " and " +
           to_string(b.mode);
  if (a.spheres != b.spheres || a.sphere_segments != b.sphere_segments)
    return "the renders differ in how spheres were drawn (spheres, sphere_segments)";
  const Scene& sa = *a.scene;
  const Scene& sb = *b.scene;
  if (&sa == &sb) return "";
  if (sa.source != sb.source)
    return "the renders are of different scenes: " + sa.source + " and " + sb.source;
  if (!same_camera(sa.camera, sb.camera)) return "the renders differ in camera";
  if (!same_image(sa.image, sb.image))
    return "the renders differ in image settings (samples per pixel, exposure or background)";
  if (sa.ambient != sb.ambient || !same_all(sa.lights, sb.lights, same_light))
    return "the renders differ in lights";
  if (!same_all(sa.materials, sb.materials, same_material) ||
      !same_all(sa.textures, sb.textures, same_texture))
    return "the renders differ in materials";
  if (!same_all(sa.objects, sb.objects, same_object))
    return "the renders are of different scenes of one source: " + sa.source + " (objects differ)";
  return "";
}

py::object compare(const PyRender& a, const PyRender& b, bool allow_different) {
  const RenderResult& ra = *a.result;
  const RenderResult& rb = *b.result;
  const FrameBuffers& fa = ra.output.buffers;
  const FrameBuffers& fb = rb.output.buffers;
  if (fa.width != fb.width || fa.height != fb.height)
    throw BadInputError("compare: the renders differ in size: " + std::to_string(fa.width) + "x" +
                        std::to_string(fa.height) + " and " + std::to_string(fb.width) + "x" +
                        std::to_string(fb.height));
  if (!allow_different) {
    if (const std::string why = difference(ra, rb); !why.empty())
      throw BadInputError("compare: " + why +
                          " (rvr compare compares renders of one scene; allow_different=True "
                          "compares them anyway)");
  }
  CompareOptions options;
  // Which effects act, and so which masks the metrics' effects hold (ra.mode == rb.mode unless
  // allow_different).
  options.mode = ra.mode;
  // As compare_renderers sets them for the command line: the geometry the mismatch classes
  // and depth-outlier causes are judged on (only when both renders drew spheres alike).
  if (ra.spheres == rb.spheres && ra.sphere_segments == rb.sphere_segments) {
    if (ra.spheres == SphereMode::Mesh)
      options.sphere_segments = ra.sphere_segments;
    else
      options.polygon_sphere_segments = ra.sphere_segments;
  }
  CompareResult result = compare_rendered(*ra.scene, {compared(ra), compared(rb)}, options);
  ReportContext context;
  context.mode = to_string(ra.mode);
  context.load_seconds = ra.times.load;
  context.command_line = "rvr.compare(" + ra.renderer + ", " + rb.renderer + ")";
  const ReportInput report = report_input(*ra.scene, result, options, context);
  return py::module_::import("json").attr("loads")(metrics_json(report));
}

// An image from a file, an array (H x W or H x W x C) or a render's colour.
Image image_of(const char* name, const py::object& value) {
  if (py::isinstance<PyRender>(value))
    return colour_image(py::cast<const PyRender&>(value).result->output.buffers);
  if (py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__"))
    return take(read_image(path_of(name, value)));
  using Floats = py::array_t<float, py::array::c_style | py::array::forcecast>;
  Floats pixels;
  try {
    pixels = Floats::ensure(value);
  } catch (const py::error_already_set&) {
    pixels = {};
  }
  if (!pixels || (pixels.ndim() != 2 && pixels.ndim() != 3) || pixels.size() == 0)
    throw BadInputError(
        std::string(name) +
        ": expected an image file, an H x W or H x W x C array or an "
        "rvr.Render, got " +
        (pixels ? "an array of shape " + py::cast<std::string>(py::str(pixels.attr("shape")))
                : type_name(value)));
  Image image;
  image.height = int(pixels.shape(0));
  image.width = int(pixels.shape(1));
  image.channels = pixels.ndim() == 3 ? int(pixels.shape(2)) : 1;
  image.pixels.assign(pixels.data(), pixels.data() + pixels.size());
  return image;
}

py::dict diff(const py::object& a_in, const py::object& b_in, double fail, double fail_percent,
              std::optional<double> hard_fail, double warn, double warn_percent,
              std::optional<double> hard_warn, std::optional<double> fail_above,
              const py::object& out_in) {
  DiffThresholds t;
  t.fail = float(fail);
  t.fail_percent = float(fail_percent);
  if (hard_fail) t.hard_fail = float(*hard_fail);
  t.warn = float(warn);
  t.warn_percent = float(warn_percent);
  if (hard_warn) t.hard_warn = float(*hard_warn);
  const std::string out = path_of("out", out_in);
  Image a = image_of("a", a_in);
  Image b = image_of("b", b_in);
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

// rvr.diff's defaults as the stub writes them: idiff's (DiffThresholds), exactly.
constexpr double kFail = 1e-6, kWarn = 1e-6, kPercent = 0.0;
static_assert(float(kFail) == DiffThresholds{}.fail && float(kWarn) == DiffThresholds{}.warn &&
              float(kPercent) == DiffThresholds{}.fail_percent &&
              float(kPercent) == DiffThresholds{}.warn_percent);

}  // namespace

void bind_compare(py::module_& m) {
  m.def("compare", &compare, py::arg("a"), py::arg("b"), py::kw_only(),
        py::arg("allow_different") = false, docs::compare);
  m.def("diff", &diff, py::arg("a"), py::arg("b"), py::kw_only(), py::arg("fail") = kFail,
        py::arg("fail_percent") = kPercent, py::arg("hard_fail") = py::none(),
        py::arg("warn") = kWarn, py::arg("warn_percent") = kPercent,
        py::arg("hard_warn") = py::none(), py::arg("fail_above") = py::none(), py::arg("out") = "",
        docs::diff);
}

}  // namespace rvr::python
