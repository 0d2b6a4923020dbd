// rvr.Scene and rvr.scenes(): scenes loaded through the command line's loader.
#include "py_scene.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // IWYU pragma: keep (type casters for std containers)
#include <stddef.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <glm/glm.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "arguments.h"
#include "bindings.h"
#include "errors.h"
#include "rvr/core/expected.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/renderer.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/scene_io/scene_for_render.h"
#include "rvr/scene_io/scene_loader.h"
#include "rvr/scene_io/scene_writer.h"
#include "stub_docs.h"

namespace py = pybind11;

namespace rvr::python {
namespace {

int checked_side(const char* name, int value) {
  if (value < 1 || value > kMaxImageSize)
    throw BadInputError(std::string(name) + ": must be 1 to " + std::to_string(kMaxImageSize) +
                        ", got " + std::to_string(value));
  return value;
}

int checked_spp(int value) {
  if (value < 1 || value > 65536)
    throw BadInputError("spp: must be 1 to 65536, got " + std::to_string(value));
  return value;
}

glm::vec3 vec3_of(const char* name, const py::handle& value) {
  std::vector<float> v = py::cast<std::vector<float>>(value);
  if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    throw BadInputError(std::string(name) + ": expected three finite numbers");
  return {v[0], v[1], v[2]};
}

py::dict camera_dict(const Camera& c) {
  py::dict d;
  d["eye"] = py::make_tuple(c.eye.x, c.eye.y, c.eye.z);
  d["target"] = py::make_tuple(c.target.x, c.target.y, c.target.z);
  d["up"] = py::make_tuple(c.up.x, c.up.y, c.up.z);
  d["fov"] = c.fov_y_deg;
  return d;
}

// `camera` as the scene loader reads it (its checks, its unit-length up), through a document
// holding only the camera: one implementation of what a valid camera is.
Camera loaded_camera(const Camera& c) {
  auto vec = [](const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  const nlohmann::json document = {{"format", "rvr-scene/1"},
                                   {"camera",
                                    {{"eye", vec(c.eye)},
                                     {"target", vec(c.target)},
                                     {"up", vec(c.up)},
                                     {"fov_y_deg", c.fov_y_deg},
                                     {"near", c.near},
                                     {"far", c.far},
                                     {"aperture_radius", c.aperture_radius},
                                     {"focus_distance", c.focus_distance}}}};
  return take(parse_scene(document.dump(), "camera", ".")).camera;
}

// Sets the keys given (eye, target, up, fov); the others stay.
void set_camera(Camera& camera, const py::dict& d) {
  for (const auto& [key, value] : d) {
    const std::string k = py::cast<std::string>(key);
    if (k == "eye")
      camera.eye = vec3_of("camera.eye", value);
    else if (k == "target")
      camera.target = vec3_of("camera.target", value);
    else if (k == "up")
      camera.up = vec3_of("camera.up", value);
    else if (k == "fov")
      camera.fov_y_deg = py::cast<float>(value);
    else
      throw BadInputError("camera: unknown key '" + k + "' (known: eye, target, up, fov)");
  }
  camera = loaded_camera(camera);
}

UpAxis up_axis_of(const std::string& s) {
  if (s == "auto") return UpAxis::Auto;
  if (s == "y") return UpAxis::Y;
  if (s == "z") return UpAxis::Z;
  throw BadInputError("up_axis: expected auto, y or z, got '" + s + "'");
}

FromFile from_file_of(const char* name, const std::string& s) {
  if (s == "file") return FromFile::File;
  if (s == "auto") return FromFile::Auto;
  throw BadInputError(std::string(name) + ": expected file or auto, got '" + s + "'");
}

SceneOverrides overrides_of(std::optional<int> width, std::optional<int> height,
                            std::optional<float> exposure,
                            const std::optional<py::sequence>& camera_from) {
  SceneOverrides o;
  if (width) o.width = checked_side("width", *width);
  if (height) o.height = checked_side("height", *height);
  if (exposure) o.exposure = *exposure;
  if (camera_from) o.view_from = vec3_of("camera_from", *camera_from);
  return o;
}

// A dict's JSON text, numpy arrays and numbers written as lists and numbers.
std::string json_text(const py::dict& document) {
  const py::cpp_function plain([](const py::object& value) -> py::object {
    if (py::hasattr(value, "tolist")) return value.attr("tolist")();
    throw BadInputError("dict: a " + type_name(value) + " is not a JSON value");
  });
  return py::cast<std::string>(
      py::module_::import("json").attr("dumps")(document, py::arg("default") = plain));
}

// The scene of `request`, with the camera settings of `camera` applied after loading.
PyScene loaded(const SceneRequest& request, const std::optional<py::dict>& camera) {
  PyScene s;
  Scene scene = take(load_scene_for_render(request, RenderOptions{}, &s.load_seconds));
  if (camera) set_camera(scene.camera, *camera);
  s.scene = std::make_shared<Scene>(std::move(scene));
  s.limits = request.limits;
  return s;
}

PyScene load(const py::object& source, std::optional<int> width, std::optional<int> height,
             std::optional<int> spp, std::optional<float> exposure,
             std::optional<py::sequence> camera_from, const std::string& up_axis,
             const std::string& model_camera, const std::string& model_lights,
             std::optional<py::dict> camera) {
  SceneRequest request;
  if (py::isinstance<py::dict>(source)) {
    request.spec = "dict";
    request.load = [text = json_text(source)](const SceneOverrides& o) {
      return load_scene_text(text, "dict", "", o);
    };
  } else {
    request.spec = path_of("source", source, "a path, 'builtin:NAME' or a dict");
  }
  request.overrides = overrides_of(width, height, exposure, camera_from);
  if (spp) request.spp = checked_spp(*spp);
  request.overrides.up = up_axis_of(up_axis);
  request.overrides.camera = from_file_of("model_camera", model_camera);
  request.overrides.lights = from_file_of("model_lights", model_lights);
  return loaded(request, camera);
}

// An array of ROWS x COLUMNS of T from `value` (any array-like; a flat array of ROWS*COLUMNS
// values when `flat_ok`), each row as V; bad input naming `name` otherwise.
template <class V, class T>
std::vector<V> rows_of(const char* name, const py::object& value, bool flat_ok = false) {
  constexpr py::ssize_t kColumns = V::length();
  py::array_t<T, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(value);
  } catch (const py::error_already_set&) {
    a = {};
  }
  if (!a) throw BadInputError(std::string(name) + ": expected an array of numbers");
  const bool rows = a.ndim() == 2 && a.shape(1) == kColumns;
  const bool flat = flat_ok && a.ndim() == 1 && a.shape(0) % kColumns == 0;
  if (!rows && !flat)
    throw BadInputError(std::string(name) + ": expected an N x " + std::to_string(kColumns) +
                        " array" +
                        (flat_ok ? " (or N*" + std::to_string(kColumns) + " values)" : "") +
                        ", got shape " + py::cast<std::string>(py::str(a.attr("shape"))));
  std::vector<V> out(size_t(a.size() / kColumns));
  const T* data = a.data();
  for (size_t i = 0; i < out.size(); ++i)
    for (py::ssize_t k = 0; k < kColumns; ++k)
      out[i][int(k)] = data[i * size_t(kColumns) + size_t(k)];
  return out;
}

// Indices: integers only (a float would be cut silently), as a signed type first, so that a
// negative one is refused rather than wrapped.
std::vector<glm::uvec3> triangles_of(const py::object& value) {
  py::array given;
  try {
    given = py::array::ensure(value);
  } catch (const py::error_already_set&) {
    given = {};
  }
  if (given && given.size() > 0 && given.dtype().kind() != 'i' && given.dtype().kind() != 'u')
    throw BadInputError("indices: expected integers, got " +
                        py::cast<std::string>(py::str(given.dtype())));
  const std::vector<glm::i64vec3> signed_rows =
      rows_of<glm::i64vec3, int64_t>("indices", value, true);
  std::vector<glm::uvec3> out(signed_rows.size());
  for (size_t t = 0; t < out.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int64_t v = signed_rows[t][k];
      if (v < 0 || v > int64_t(UINT32_MAX))
        throw BadInputError("mesh: indices[" + std::to_string(t) + "]: vertex " +
                            std::to_string(v) + " is not a vertex index");
      out[t][k] = uint32_t(v);
    }
  }
  return out;
}

PyScene from_mesh(const py::object& vertices, const py::object& indices,
                  const std::optional<py::object>& normals,
                  const std::optional<py::object>& colours, std::optional<int> width,
                  std::optional<int> height, std::optional<int> spp, std::optional<float> exposure,
                  std::optional<py::sequence> camera_from, const std::string& up_axis,
                  std::optional<py::dict> camera) {
  TriangleMesh mesh;
  mesh.positions = rows_of<glm::vec3, float>("vertices", vertices);
  mesh.triangles = triangles_of(indices);
  if (normals) mesh.normals = rows_of<glm::vec3, float>("normals", *normals);
  if (colours) mesh.colours = rows_of<glm::vec3, float>("colors", *colours);
  if (up_axis != "y" && up_axis != "z")
    throw BadInputError("up_axis: expected y or z, got '" + up_axis + "'");
  SceneRequest request;
  request.spec = "mesh";
  request.overrides = overrides_of(width, height, exposure, camera_from);
  request.overrides.up = up_axis_of(up_axis);
  if (spp) request.spp = checked_spp(*spp);
  // Taken once: the request is not loaded again.
  auto held = std::make_shared<TriangleMesh>(std::move(mesh));
  request.load = [held](const SceneOverrides& o) {
    return load_mesh_scene(std::move(*held), "mesh", o);
  };
  return loaded(request, camera);
}

SceneDocument document(const PyScene& s, const std::string& mesh_prefix) {
  return take(write_scene(*s.scene, mesh_prefix));
}

}  // namespace

void bind_scene(py::module_& m) {
  m.def(
      "scenes",
      [] {
        py::list out;
        for (const BuiltinSceneInfo& s : builtin_scenes()) {
          py::dict d;
          d["name"] = "builtin:" + s.name;
          d["description"] = s.description;
          out.append(d);
        }
        return out;
      },
      docs::scenes);

  py::class_<PyScene>(m, "Scene", docs::Scene)
      .def(py::init(&load), py::arg("source") = "builtin:cornell", py::kw_only(),
           py::arg("width") = py::none(), py::arg("height") = py::none(),
           py::arg("spp") = py::none(), py::arg("exposure") = py::none(),
           py::arg("camera_from") = py::none(), py::arg("up_axis") = "auto",
           py::arg("model_camera") = "file", py::arg("model_lights") = "file",
           py::arg("camera") = py::none(), docs::Scene_init)
      .def_static("from_mesh", &from_mesh, py::arg("vertices"), py::arg("indices"), py::kw_only(),
                  py::arg("normals") = py::none(), py::arg("colors") = py::none(),
                  py::arg("width") = py::none(), py::arg("height") = py::none(),
                  py::arg("spp") = py::none(), py::arg("exposure") = py::none(),
                  py::arg("camera_from") = py::none(), py::arg("up_axis") = "y",
                  py::arg("camera") = py::none(), docs::Scene_from_mesh)
      .def_property_readonly(
          "source", [](const PyScene& s) { return s.scene->source; }, docs::Scene_source)
      .def_property(
          "width", [](const PyScene& s) { return s.scene->image.width; },
          [](PyScene& s, int w) { s.edit().image.width = checked_side("width", w); },
          docs::Scene_width)
      .def_property(
          "height", [](const PyScene& s) { return s.scene->image.height; },
          [](PyScene& s, int h) { s.edit().image.height = checked_side("height", h); },
          docs::Scene_height)
      .def_property(
          "spp", [](const PyScene& s) { return s.scene->image.samples_per_pixel; },
          [](PyScene& s, int n) { s.edit().image.samples_per_pixel = checked_spp(n); },
          docs::Scene_spp)
      .def_property(
          "camera", [](const PyScene& s) { return camera_dict(s.scene->camera); },
          [](PyScene& s, const py::dict& d) {
            Camera camera = s.scene->camera;
            set_camera(camera, d);
            s.edit().camera = camera;
          },
          docs::Scene_camera)
      .def_property_readonly(
          "warnings", [](const PyScene& s) { return s.scene->warnings; }, docs::Scene_warnings)
      .def(
          "to_json",
          [](const PyScene& s) {
            SceneDocument doc = document(s, "scene");
            if (!doc.mesh_files.empty())
              throw BadInputError(s.scene->source + ": has meshes of more than one triangle, " +
                                  "which rvr-scene/1 reads only from mesh files: use save(PATH)");
            return doc.json;
          },
          docs::Scene_to_json)
      .def(
          "save",
          [](const PyScene& s, const py::object& where) {
            const std::string path = path_of("path", where);
            const std::filesystem::path out(path);
            SceneDocument doc = document(s, out.stem().string());
            for (const SceneMeshFile& f : doc.mesh_files)
              check(write_text_file((out.parent_path() / f.name).string(), f.bytes));
            check(write_text_file(path, doc.json));
          },
          py::arg("path"), docs::Scene_save)
      .def("__repr__", [](const PyScene& s) {
        return "rvr.Scene('" + s.scene->source + "', " + std::to_string(s.scene->image.width) +
               "x" + std::to_string(s.scene->image.height) + ")";
      });
}

}  // namespace rvr::python
