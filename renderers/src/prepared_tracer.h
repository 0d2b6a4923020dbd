// The tracers' prepare hook: the acceleration structure built once for frames to come.
#pragma once

#include <memory>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/renderers/prepared_renderer.h"

namespace rvr {

// `accel` is what answers the queries: the options' for raytrace, Embree for embree.
Expected<std::unique_ptr<PreparedRenderer>> prepare_tracer(const Scene& scene,
                                                           const RenderOptions& options,
                                                           AccelKind accel);

}  // namespace rvr
