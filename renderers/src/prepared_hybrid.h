// The hybrids' prepare hook: the tracer's geometry built once for frames to come (the z-buffer
// pass is part of every frame, as it is of the raster's).
#pragma once

#include <memory>

#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/hybrid/hybrid_renderer.h"
#include "rvr/renderers/prepared_renderer.h"

namespace rvr {

Expected<std::unique_ptr<PreparedRenderer>> prepare_hybrid(const Scene& scene,
                                                           const RenderOptions& options,
                                                           ZBufferKind zbuffer, GlBackend gl);

}  // namespace rvr
