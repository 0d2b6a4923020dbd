// What the renderers run on, for `rvr info` and bug reports: the GL context the raster renderer
// would get and the versions of the libraries the tracers use. The command line asks here, so
// that it includes nothing from raster/ or raytrace/.
#pragma once

#include <string>

#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"

namespace rvr {

// Makes a GL context as the raster renderer would with `backend` and reads its strings; an
// Internal error when no usable context exists.
Expected<GlInfo> query_renderer_gl(GlBackend backend);

struct TracerLibraries {
  std::string embree;  // Embree's version
  std::string tbb;     // oneTBB's version
};
TracerLibraries tracer_libraries();

}  // namespace rvr
