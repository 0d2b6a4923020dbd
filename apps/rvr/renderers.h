// Every renderer by its command-line name; the CLI, the tests and the benchmarks use this.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rvr/raster/gl_rasterizer.h"
#include "rvr/shared/expected.h"
#include "rvr/shared/renderer.h"

namespace rvr {

// In the order they are documented: "raster", "raytrace".
std::vector<std::string> renderer_names();

// A bad name is a BadInput error listing the known ones. `gl` picks the raster's GL back end.
Expected<std::unique_ptr<Renderer>> make_renderer(const std::string& name,
                                                  GlBackend gl = GlBackend::Default);

}  // namespace rvr
