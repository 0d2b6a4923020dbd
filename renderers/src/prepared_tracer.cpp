#include "prepared_tracer.h"

#include <variant>

#include "prepared_over_geometry.h"
#include "rvr/raytrace/ray_tracer.h"

namespace rvr {

Expected<std::unique_ptr<PreparedRenderer>> prepare_tracer(const Scene& scene,
                                                           const RenderOptions& options,
                                                           AccelKind accel) {
  return PreparedOverGeometry<RayTracer>::prepare(scene, options, accel);
}

}  // namespace rvr
