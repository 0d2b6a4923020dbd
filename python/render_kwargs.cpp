#include "render_kwargs.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "errors.h"
#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/render_option_table.h"
#include "suggest.h"

namespace py = pybind11;

namespace rvr::python {
namespace {

// A keyword's Python value as the text the table checks: numbers as numbers, booleans as on/off
// (hiz=True as hiz="on"), names as they are.
std::string value_text(const RenderOptionSpec& spec, const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return py::cast<bool>(value) ? "on" : "off";
  switch (spec.type) {
    case OptionType::Integer:
      return std::to_string(py::cast<long long>(value));
    case OptionType::Unsigned:
      return std::to_string(py::cast<unsigned long long>(value));
    case OptionType::Real:
      return py::str(py::float_(py::cast<double>(value))).cast<std::string>();
    case OptionType::Flag:
    case OptionType::Choice:
      break;
  }
  return py::cast<std::string>(value);
}

// Stores keyword `name`'s value, or raises rvr.BadInput naming the keyword (a choice's error
// asks "did you mean", as the command line's).
void set_keyword(RenderOptions& options, const RenderOptionSpec& spec, const py::handle& value) {
  const std::string text = value_text(spec, value);
  const Status status = set_render_option(options, spec, text);
  if (status) return;
  std::string message = status.error().message;
  if (spec.type == OptionType::Choice)
    message =
        cli::not_one_of(text, std::vector<std::string>(spec.choices.begin(), spec.choices.end()));
  throw BadInputError(std::string(spec.name) + ": " + message);
}

// The keywords: the table's options (mode and threads are render's own arguments) and gl.
std::string known_keywords() {
  std::string known;
  for (const RenderOptionSpec& spec : render_option_table())
    if (spec.name != "mode" && spec.name != "threads")
      known += (known.empty() ? "" : ", ") + std::string(spec.name);
  return known + ", gl";
}

}  // namespace

RenderSettings render_settings(const std::string& mode, int threads, const py::kwargs& kwargs) {
  RenderSettings s;
  set_keyword(s.options, *find_render_option("mode"), py::str(mode));
  set_keyword(s.options, *find_render_option("threads"), py::int_(threads));
  if (threads != 0) s.given.emplace_back("threads");  // render's argument, given unless 0
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::cast<std::string>(key);
    if (name == "gl") {
      const std::string gl = py::cast<std::string>(value);
      const std::optional<GlBackend> backend = parse_gl_backend(gl);
      if (!backend) throw BadInputError("gl: " + cli::not_one_of(gl, gl_backend_names()));
      s.config.gl = *backend;
      continue;
    }
    const RenderOptionSpec* spec = find_render_option(name);
    if (!spec || name == "mode" || name == "threads")
      throw BadInputError("unknown option '" + name + "' (known: " + known_keywords() + ")");
    set_keyword(s.options, *spec, value);
    s.given.push_back(name);
  }
  return s;
}

}  // namespace rvr::python
