// rvr.render, rvr.Render and rvr.renderers(): the renderer table's renderers, rendering with the
// GIL released.
#include "py_render.h"

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // IWYU pragma: keep (type casters for std containers)
#include <stdint.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <utility>
#include <variant>
#include <vector>

#include "bindings.h"
#include "errors.h"
#include "numpy_views.h"
#include "py_scene.h"
#include "render_job.h"
#include "render_kwargs.h"
#include "rvr/renderers/registry.h"
#include "rvr/shared/framebuffers.h"
#include "rvr/shared/image_io.h"
#include "rvr/shared/limits.h"

namespace py = pybind11;

namespace rvr::python {
namespace {

py::object json_loads(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

PyRender render(const PyScene& scene, const std::string& renderer, const std::string& mode,
                int threads, const py::kwargs& kwargs) {
  RenderSettings settings = render_settings(mode, threads, kwargs);
  check(check_limits(*scene.scene, settings.options, scene.limits));
  std::unique_ptr<Renderer> made = take(make_renderer(renderer, settings.config));
  auto result = std::make_shared<RenderResult>();
  result->renderer = renderer;
  result->scene = scene.scene;
  result->mode = settings.options.mode;
  result->times.load = scene.load_seconds;
  RenderResultWithTime done = render_interruptibly(scene.scene, std::move(made), settings.options);
  result->output = take(std::move(done.output));
  result->times.render = done.seconds;
  result->stats_json = render_stats_json(result->renderer, *result->scene, result->mode,
                                         result->times, result->output);
  return PyRender{std::move(result)};
}

// PNG bytes of the colour, through the image writer the command line uses (sRGB, 8 bits).
py::bytes png_bytes(const PyRender& r) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string path =
      (dir / ("rvr-python-" + std::to_string(::getpid()) + "-" +
              std::to_string(reinterpret_cast<uintptr_t>(r.result.get())) + ".png"))
          .string();
  check(write_image(path, color_image(r.result->output.buffers)));
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  std::filesystem::remove(path);
  return py::bytes(bytes.str());
}

std::vector<py::ssize_t> shape(const PyRender& r, int channels = 0) {
  const FrameBuffers& fb = r.result->output.buffers;
  std::vector<py::ssize_t> s{fb.height, fb.width};
  if (channels) s.push_back(channels);
  return s;
}

py::list renderer_table() {
  py::list out;
  for (const RendererInfo& info : renderers()) {
    py::dict d;
    d["name"] = info.name;
    d["loop_order"] = short_name(info.order);
    d["description"] = info.description;
    out.append(d);
  }
  return out;
}

void bind_render_class(py::module_& m) {
  using Buffers = const FrameBuffers&;
  auto buffers = [](const PyRender& r) -> Buffers { return r.result->output.buffers; };
  auto owner = [](const PyRender& r) { return std::shared_ptr<const void>(r.result); };
  py::class_<PyRender>(m, "Render",
                       "A finished render. Its arrays are read-only views of the render's own "
                       "buffers (no copy), rows top to bottom; they stay valid after the Render "
                       "is gone.")
      .def_property_readonly(
          "color",
          [=](const PyRender& r) {
            return view(owner(r), &buffers(r).color.data()->x, 3 * buffers(r).color.size(),
                        shape(r, 3));
          },
          "H x W x 3 float32, linear RGB.")
      .def_property_readonly(
          "depth",
          [=](const PyRender& r) {
            return view(owner(r), buffers(r).depth.data(), buffers(r).depth.size(), shape(r));
          },
          "H x W float32 view-axis depth, +inf on background.")
      .def_property_readonly(
          "object_id",
          [=](const PyRender& r) {
            return view(owner(r), reinterpret_cast<const int32_t*>(buffers(r).object_id.data()),
                        buffers(r).object_id.size(), shape(r));
          },
          "H x W int32 index into the scene's objects, -1 on background.")
      .def_property_readonly(
          "primitive_id",
          [=](const PyRender& r) {
            return view(owner(r), reinterpret_cast<const int32_t*>(buffers(r).primitive_id.data()),
                        buffers(r).primitive_id.size(), shape(r));
          },
          "H x W int32 triangle index in the object (0 for analytic shapes), -1 on background.")
      .def_property_readonly(
          "normal",
          [=](const PyRender& r) {
            return view(owner(r), &buffers(r).normal.data()->x, 3 * buffers(r).normal.size(),
                        shape(r, 3));
          },
          "H x W x 3 float32 world-space shading normal facing the viewer, 0 on background.")
      .def_property_readonly(
          "cost",
          [=](const PyRender& r) {
            return view(owner(r), buffers(r).cost.data(), buffers(r).cost.size(), shape(r));
          },
          "H x W float32 work per pixel (nodes visited and tests, or fragments).")
      .def_property_readonly(
          "stats", [](const PyRender& r) { return json_loads(r.result->stats_json); },
          "The document `rvr render --stats` writes, as a dict.")
      .def_property_readonly(
          "warnings",
          [](const PyRender& r) {
            std::vector<std::string> w = r.result->scene->warnings;
            const auto& own = r.result->output.warnings;
            w.insert(w.end(), own.begin(), own.end());
            return w;
          },
          "The scene loader's warnings, then the renderer's.")
      .def_property_readonly(
          "renderer", [](const PyRender& r) { return r.result->renderer; }, "The renderer's name.")
      .def_property_readonly(
          "seconds", [](const PyRender& r) { return r.result->times.render; },
          "The render's wall time.")
      .def("_repr_png_", &png_bytes, "The colour as PNG bytes (sRGB), for Jupyter.")
      .def("__repr__", [](const PyRender& r) {
        const FrameBuffers& fb = r.result->output.buffers;
        return "rvr.Render('" + r.result->renderer + "', '" + r.result->scene->source + "', " +
               std::to_string(fb.width) + "x" + std::to_string(fb.height) + ")";
      });
}

}  // namespace

void bind_render(py::module_& m) {
  m.def("renderers", &renderer_table,
        "The renderer table: a list of dicts {name, loop_order (triangle-major, pixel-major, "
        "hybrid), description}.");
  bind_render_class(m);
  m.def("render", &render, py::arg("scene"), py::arg("renderer"), py::arg("mode") = "local",
        py::arg("threads") = 0,
        "Renders SCENE (an rvr.Scene) with RENDERER (a name from rvr.renderers()) in MODE "
        "(visibility, local, full) on THREADS worker threads (0: every core). Other keyword "
        "options are the command line's of the same names: accel, spheres, sphere_segments, "
        "triangle_test, max_depth, seed, gl, shadow_map_size, shadow_bias, shadow_pcf, hiz, "
        "depth_format. The GIL is released while rendering; Ctrl-C cancels the render (it stops "
        "at its next tile or chunk) and raises KeyboardInterrupt.");
  m.def("_running_renders", &running_renders,
        "Render threads still running: 0 outside rvr.render, also after a KeyboardInterrupt.");
}

}  // namespace rvr::python
