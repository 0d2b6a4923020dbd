// rvr.render's keyword options: the render option table's (rvr/core/render_option_table.h), as
// the command line's options of the same names (docs/cli.md), and gl.
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "rvr/core/renderer.h"
#include "rvr/renderers/registry.h"

namespace rvr::python {

struct RenderSettings {
  RenderOptions options;
  RendererConfig config;
  std::vector<std::string> given;  // the table's keywords given (snake_case), for the warnings
};

// Raises rvr.BadInput for an unknown mode, option or value.
RenderSettings render_settings(const std::string& mode, int threads,
                               const pybind11::kwargs& kwargs);

}  // namespace rvr::python
