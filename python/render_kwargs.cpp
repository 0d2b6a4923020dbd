#include "render_kwargs.h"

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <map>
#include <optional>
#include <utility>

#include "errors.h"
#include "rvr/core/gl_backend.h"

namespace py = pybind11;

namespace rvr::python {
namespace {

// One of `names`, else bad input naming the option and the choices.
std::string choice(const std::string& option, const py::handle& value,
                   std::initializer_list<const char*> names) {
  const std::string s = py::cast<std::string>(value);
  std::string known;
  for (const char* n : names) {
    if (s == n) return s;
    known += (known.empty() ? "" : ", ") + std::string(n);
  }
  throw BadInputError(option + ": expected one of " + known + ", got '" + s + "'");
}

int in_range(const std::string& option, const py::handle& value, int low, int high) {
  const int v = py::cast<int>(value);
  if (v < low || v > high)
    throw BadInputError(option + ": must be " + std::to_string(low) + " to " +
                        std::to_string(high) + ", got " + std::to_string(v));
  return v;
}

using Setter = std::function<void(RenderSettings&, const py::handle&)>;

const std::map<std::string, Setter>& setters() {
  static const std::map<std::string, Setter> table = {
      {"accel",
       [](RenderSettings& s, const py::handle& v) {
         const std::string a = choice("accel", v, {"bvh", "bvh2", "none"});
         s.options.accel = a == "none"   ? AccelKind::None
                           : a == "bvh2" ? AccelKind::Bvh2
                                         : AccelKind::Bvh;
       }},
      {"spheres",
       [](RenderSettings& s, const py::handle& v) {
         s.options.spheres = choice("spheres", v, {"analytic", "mesh"}) == "mesh"
                                 ? SphereMode::Mesh
                                 : SphereMode::Analytic;
       }},
      {"sphere_segments",
       [](RenderSettings& s, const py::handle& v) {
         s.options.sphere_segments = in_range("sphere_segments", v, 3, 4096);
       }},
      {"triangle_test",
       [](RenderSettings& s, const py::handle& v) {
         s.options.triangle_test = choice("triangle_test", v, {"mt", "chapter"}) == "chapter"
                                       ? TriangleTest::Chapter
                                       : TriangleTest::MollerTrumbore;
       }},
      {"max_depth",
       [](RenderSettings& s, const py::handle& v) {
         s.options.max_depth = in_range("max_depth", v, 0, 64);
       }},
      {"seed",
       [](RenderSettings& s, const py::handle& v) { s.options.seed = py::cast<uint64_t>(v); }},
      {"gl",
       [](RenderSettings& s, const py::handle& v) {
         s.config.gl =
             choice("gl", v, {"osmesa", "egl"}) == "egl" ? GlBackend::Egl : GlBackend::OsMesa;
       }},
      {"shadow_map_size",
       [](RenderSettings& s, const py::handle& v) {
         s.options.shadow_map_size = in_range("shadow_map_size", v, 16, 8192);
       }},
      {"shadow_bias",
       [](RenderSettings& s, const py::handle& v) {
         const float bias = py::cast<float>(v);
         if (!(bias >= 0.0f && bias <= 10.0f))
           throw BadInputError("shadow_bias: must be 0 to 10, got " + std::to_string(bias));
         s.options.shadow_bias = bias;
       }},
      {"shadow_pcf",
       [](RenderSettings& s, const py::handle& v) { s.options.shadow_pcf = py::cast<bool>(v); }},
      {"hiz",
       [](RenderSettings& s, const py::handle& v) {
         s.options.hiz = py::isinstance<py::str>(v) ? choice("hiz", v, {"on", "off"}) == "on"
                                                    : py::cast<bool>(v);
       }},
      {"depth_format",
       [](RenderSettings& s, const py::handle& v) {
         s.options.depth_format =
             parse_depth_format(choice("depth_format", v, {"d24", "d32f", "d32f_reversed"}));
       }},
  };
  return table;
}

}  // namespace

RenderSettings render_settings(const std::string& mode, int threads, const py::kwargs& kwargs) {
  RenderSettings s;
  if (mode == "visibility")
    s.options.mode = RenderMode::Visibility;
  else if (mode == "local")
    s.options.mode = RenderMode::Local;
  else if (mode == "full")
    s.options.mode = RenderMode::Full;
  else
    throw BadInputError("mode: expected one of visibility, local, full, got '" + mode + "'");
  if (threads < 0 || threads > 1024)
    throw BadInputError("threads: must be 0 to 1024, got " + std::to_string(threads));
  s.options.threads = threads;
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::cast<std::string>(key);
    auto it = setters().find(name);
    if (it == setters().end()) {
      std::string known;
      for (const auto& [k, setter] : setters()) known += (known.empty() ? "" : ", ") + k;
      throw BadInputError("unknown option '" + name + "' (known: " + known + ")");
    }
    it->second(s, value);
  }
  return s;
}

}  // namespace rvr::python
