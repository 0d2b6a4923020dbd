// rvr.Scene and rvr.scenes(): scenes loaded through the command line's loader.
#include "py_scene.h"

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // IWYU pragma: keep (type casters for std containers)

#include <array>
#include <cmath>
#include <filesystem>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "errors.h"
#include "rvr/shared/image_io.h"
#include "rvr/shared/image_sample.h"
#include "rvr/shared/isa.h"
#include "rvr/shared/renderer.h"
#include "rvr/shared/scene_for_render.h"
#include "rvr/shared/scene_loader.h"
#include "rvr/shared/scene_writer.h"

namespace py = pybind11;

namespace rvr::python {
namespace {

constexpr int kMaxImageSide = 16384;  // as the command line's --width and --height

int checked_side(const char* name, int value) {
  if (value < 1 || value > kMaxImageSide)
    throw BadInputError(std::string(name) + ": must be 1 to 16384, got " + std::to_string(value));
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

PyScene load(const std::string& source, std::optional<int> width, std::optional<int> height,
             std::optional<int> spp, std::optional<float> exposure,
             std::optional<py::sequence> camera_from, const std::string& up_axis,
             const std::string& model_camera, const std::string& model_lights,
             std::optional<py::dict> camera) {
  SceneRequest request;
  request.spec = source;
  if (width) request.overrides.width = checked_side("width", *width);
  if (height) request.overrides.height = checked_side("height", *height);
  if (spp) request.spp = checked_spp(*spp);
  if (exposure) request.overrides.exposure = *exposure;
  if (camera_from) request.overrides.view_from = vec3_of("camera_from", *camera_from);
  request.overrides.up = up_axis_of(up_axis);
  request.overrides.camera = from_file_of("model_camera", model_camera);
  request.overrides.lights = from_file_of("model_lights", model_lights);
  PyScene s;
  Scene scene = take(load_scene_for_render(request, RenderOptions{}, &s.load_seconds));
  if (camera) set_camera(scene.camera, *camera);
  s.scene = std::make_shared<Scene>(std::move(scene));
  s.limits = request.limits;
  return s;
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
      "The built-in scenes: a list of dicts {name ('builtin:cornell'), description}, as "
      "`rvr scenes` lists them.");

  py::class_<PyScene>(m, "Scene",
                      "A scene: a scene file (rvr-scene/1), a model file Assimp reads, or "
                      "'builtin:NAME', loaded by the command line's loader.")
      .def(py::init(&load), py::arg("source") = "builtin:cornell", py::kw_only(),
           py::arg("width") = py::none(), py::arg("height") = py::none(),
           py::arg("spp") = py::none(), py::arg("exposure") = py::none(),
           py::arg("camera_from") = py::none(), py::arg("up_axis") = "auto",
           py::arg("model_camera") = "file", py::arg("model_lights") = "file",
           py::arg("camera") = py::none(),
           "Loads SOURCE with the command line's overrides (--width, --height, --spp, "
           "--exposure, --camera-from, --up, --camera, --lights); camera={'eye', 'target', "
           "'up', 'fov'} then replaces those camera settings. Raises rvr.BadInput with the "
           "command line's message.")
      .def_property_readonly(
          "source", [](const PyScene& s) { return s.scene->source; },
          "What was loaded: 'builtin:cornell' or the file's path.")
      .def_property(
          "width", [](const PyScene& s) { return s.scene->image.width; },
          [](PyScene& s, int w) { s.edit().image.width = checked_side("width", w); },
          "Image width in pixels.")
      .def_property(
          "height", [](const PyScene& s) { return s.scene->image.height; },
          [](PyScene& s, int h) { s.edit().image.height = checked_side("height", h); },
          "Image height in pixels.")
      .def_property(
          "spp", [](const PyScene& s) { return s.scene->image.samples_per_pixel; },
          [](PyScene& s, int n) { s.edit().image.samples_per_pixel = checked_spp(n); },
          "Samples per pixel.")
      .def_property(
          "camera", [](const PyScene& s) { return camera_dict(s.scene->camera); },
          [](PyScene& s, const py::dict& d) {
            Camera camera = s.scene->camera;
            set_camera(camera, d);
            s.edit().camera = camera;
          },
          "The camera as a dict {eye, target, up, fov (vertical, degrees)}; assigning a dict "
          "sets the keys it has.")
      .def_property_readonly(
          "warnings", [](const PyScene& s) { return s.scene->warnings; },
          "What the loader had to change or drop, each naming the file.")
      .def(
          "to_json",
          [](const PyScene& s) {
            SceneDocument doc = document(s, "scene");
            if (!doc.mesh_files.empty())
              throw BadInputError(s.scene->source + ": has meshes of more than one triangle, " +
                                  "which rvr-scene/1 reads only from mesh files: use save(PATH)");
            return doc.json;
          },
          "The scene as rvr-scene/1 JSON text (as `rvr scenes --export`).")
      .def(
          "save",
          [](const PyScene& s, const std::string& path) {
            const std::filesystem::path out(path);
            SceneDocument doc = document(s, out.stem().string());
            for (const SceneMeshFile& f : doc.mesh_files)
              check(write_text_file((out.parent_path() / f.name).string(), f.bytes));
            check(write_text_file(path, doc.json));
          },
          py::arg("path"), "Writes the scene as rvr-scene/1 to PATH, its meshes as PLY beside it.")
      .def("__repr__", [](const PyScene& s) {
        return "rvr.Scene('" + s.scene->source + "', " + std::to_string(s.scene->image.width) +
               "x" + std::to_string(s.scene->image.height) + ")";
      });
}

}  // namespace rvr::python
