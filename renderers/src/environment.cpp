// The renderers' environment, read from raster/ and raytrace/ for the command line.
#include "rvr/renderers/environment.h"

#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"

namespace rvr {

Expected<GlInfo> query_renderer_gl(GlBackend backend) {
  return query_gl_info(backend);
}

TracerLibraries tracer_libraries() {
  return {embree_version(), tbb_version()};
}

}  // namespace rvr
