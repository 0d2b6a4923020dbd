// rvr.render, rvr.Render and rvr.renderers(): the renderer table's renderers, rendering with the
// GIL released.
#include "py_render.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // IWYU pragma: keep (type casters for std containers)
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "arguments.h"
#include "bindings.h"
#include "errors.h"
#include "numpy_views.h"
#include "py_scene.h"
#include "render_job.h"
#include "render_kwargs.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/limits.h"
#include "rvr/core/render_option_table.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/registry.h"
#include "stub_docs.h"
#include "suggest.h"

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
  Expected<std::unique_ptr<Renderer>> maybe = make_renderer(renderer, settings.config);
  if (!maybe) {
    // A name not in the table: as the command line says it of -r, naming the argument.
    std::vector<std::string> names;
    for (const RendererInfo& info : renderers()) names.push_back(info.name);
    if (std::find(names.begin(), names.end(), renderer) == names.end())
      throw BadInputError("renderer: " + cli::not_one_of(renderer, names));
  }
  std::unique_ptr<Renderer> made = take(std::move(maybe));
  auto result = std::make_shared<RenderResult>();
  result->renderer = renderer;
  result->scene = scene.scene;
  result->mode = settings.options.mode;
  result->spheres = settings.options.spheres;
  result->sphere_segments = settings.options.sphere_segments;
  result->times.load = scene.load_seconds;
  RenderResultWithTime done = render_interruptibly(scene.scene, std::move(made), settings.options);
  result->output = take(std::move(done.output));
  for (std::string& w : unread_option_warnings(settings.given, renderer, false))
    result->output.warnings.push_back(std::move(w));
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
  check(write_image(path, colour_image(r.result->output.buffers)));
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

// The level of detail sampled; a render with no textured surface keeps none (an empty buffer),
// which reads as NaN everywhere, as its AOV file does.
py::array_t<float> lod(const PyRender& r) {
  const FrameBuffers& fb = r.result->output.buffers;
  if (!fb.lod.empty())
    return view(std::shared_ptr<const void>(r.result), fb.lod.data(), fb.lod.size(), shape(r));
  auto nan = std::make_shared<const std::vector<float>>(fb.pixel_count(),
                                                        std::numeric_limits<float>::quiet_NaN());
  return view(std::shared_ptr<const void>(nan), nan->data(), nan->size(), shape(r));
}

// How a z-buffer answered each pixel's effect; a render that answered none (a tracer's, or not
// full mode) keeps an empty buffer, which reads as 0 (none) everywhere.
py::array_t<uint8_t> answer(const PyRender& r) {
  const FrameBuffers& fb = r.result->output.buffers;
  if (fb.answer.size() == fb.pixel_count())
    return view(std::shared_ptr<const void>(r.result), fb.answer.data(), fb.answer.size(),
                shape(r));
  auto none = std::make_shared<const std::vector<uint8_t>>(fb.pixel_count(), uint8_t(0));
  return view(std::shared_ptr<const void>(none), none->data(), none->size(), shape(r));
}

// Writes as `rvr render -o PATH --aov AOVS` does.
void save(const PyRender& r, const py::object& where, const py::object& aovs) {
  const std::string path = path_of("path", where);
  const std::vector<std::string> names = names_of("aovs", aovs);
  const std::vector<std::string> known{"depth", "id", "normal", "cost", "lod"};
  for (const std::string& name : names) {
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw BadInputError("aovs: expected names of depth, id, normal, cost, lod, got '" + name +
                          "'");
  }
  const FrameBuffers& fb = r.result->output.buffers;
  check(write_image(path, colour_image(fb)));
  if (!names.empty()) check(write_aovs(path, fb, names));
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
  py::class_<PyRender>(m, "Render", docs::Render)
      .def_property_readonly(
          "color",
          [=](const PyRender& r) {
            return view(owner(r), &buffers(r).colour.data()->x, 3 * buffers(r).colour.size(),
                        shape(r, 3));
          },
          docs::Render_color)
      .def_property_readonly(
          "depth",
          [=](const PyRender& r) {
            return view(owner(r), buffers(r).depth.data(), buffers(r).depth.size(), shape(r));
          },
          docs::Render_depth)
      .def_property_readonly(
          "object_id",
          [=](const PyRender& r) {
            return view(owner(r), reinterpret_cast<const int32_t*>(buffers(r).object_id.data()),
                        buffers(r).object_id.size(), shape(r));
          },
          docs::Render_object_id)
      .def_property_readonly(
          "primitive_id",
          [=](const PyRender& r) {
            return view(owner(r), reinterpret_cast<const int32_t*>(buffers(r).primitive_id.data()),
                        buffers(r).primitive_id.size(), shape(r));
          },
          docs::Render_primitive_id)
      .def_property_readonly(
          "normal",
          [=](const PyRender& r) {
            return view(owner(r), &buffers(r).normal.data()->x, 3 * buffers(r).normal.size(),
                        shape(r, 3));
          },
          docs::Render_normal)
      .def_property_readonly(
          "cost",
          [=](const PyRender& r) {
            return view(owner(r), buffers(r).cost.data(), buffers(r).cost.size(), shape(r));
          },
          docs::Render_cost)
      .def_property_readonly("lod", &lod, docs::Render_lod)
      .def_property_readonly("answer", &answer, docs::Render_answer)
      .def_property_readonly(
          "stats", [](const PyRender& r) { return json_loads(r.result->stats_json); },
          docs::Render_stats)
      .def_property_readonly(
          "warnings",
          [](const PyRender& r) {
            std::vector<std::string> w = r.result->scene->warnings;
            const auto& own = r.result->output.warnings;
            w.insert(w.end(), own.begin(), own.end());
            return w;
          },
          docs::Render_warnings)
      .def_property_readonly(
          "renderer", [](const PyRender& r) { return r.result->renderer; }, docs::Render_renderer)
      .def_property_readonly(
          "seconds", [](const PyRender& r) { return r.result->times.render; }, docs::Render_seconds)
      .def("save", &save, py::arg("path"), py::arg("aovs") = py::tuple(), docs::Render_save)
      .def("_repr_png_", &png_bytes, docs::Render_repr_png)
      .def("__repr__", [](const PyRender& r) {
        const FrameBuffers& fb = r.result->output.buffers;
        return "rvr.Render('" + r.result->renderer + "', '" + r.result->scene->source + "', " +
               std::to_string(fb.width) + "x" + std::to_string(fb.height) + ")";
      });
}

}  // namespace

void bind_render(py::module_& m) {
  m.def("renderers", &renderer_table, docs::renderers);
  bind_render_class(m);
  m.def("render", &render, py::arg("scene"), py::arg("renderer"), py::arg("mode") = "local",
        py::arg("threads") = 0, docs::render);
  m.def("_running_renders", &running_renders, docs::running_renders);
}

}  // namespace rvr::python
