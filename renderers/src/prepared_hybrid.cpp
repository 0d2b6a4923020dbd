#include "prepared_hybrid.h"

#include <variant>

#include "prepared_over_geometry.h"

namespace rvr {

Expected<std::unique_ptr<PreparedRenderer>> prepare_hybrid(const Scene& scene,
                                                           const RenderOptions& options,
                                                           ZBufferKind zbuffer, GlBackend gl) {
  return PreparedOverGeometry<HybridRenderer>::prepare(scene, options, options.accel, zbuffer, gl);
}

}  // namespace rvr
