#include "renderers.h"

#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raster/soft_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"

namespace rvr {

std::vector<std::string> renderer_names() {
  return {"raster", "softraster", "raytrace", "embree"};
}

Expected<std::unique_ptr<Renderer>> make_renderer(const std::string& name, GlBackend gl) {
  if (name == "raster") return std::unique_ptr<Renderer>(std::make_unique<GlRasterizer>(gl));
  if (name == "softraster") return std::unique_ptr<Renderer>(std::make_unique<SoftRasterizer>());
  if (name == "raytrace") return std::unique_ptr<Renderer>(std::make_unique<RayTracer>());
  if (name == "embree")
    return std::unique_ptr<Renderer>(std::make_unique<RayTracer>(AccelKind::Embree));
  std::string known;
  for (const std::string& n : renderer_names()) known += (known.empty() ? "" : ", ") + n;
  return bad_input("unknown renderer '" + name + "' (known: " + known + ")");
}

}  // namespace rvr
