// rvr.render's keyword options, as the command line's common options of the same names
// (docs/cli.md): accel, spheres, sphere_segments, triangle_test, max_depth, seed, gl,
// shadow_map_size, shadow_bias, shadow_pcf, hiz, depth_format.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "rvr/core/renderer.h"
#include "rvr/renderers/registry.h"

namespace rvr::python {

struct RenderSettings {
  RenderOptions options;
  RendererConfig config;
};

// Raises rvr.BadInput for an unknown mode, option or value.
RenderSettings render_settings(const std::string& mode, int threads,
                               const pybind11::kwargs& kwargs);

}  // namespace rvr::python
