// The tracers' prepare hook: the acceleration structure built once for frames to come.
#pragma once

#include <memory>

#include "rvr/renderers/prepared_renderer.h"
#include "rvr/shared/expected.h"
#include "rvr/shared/renderer.h"
#include "rvr/shared/scene.h"

namespace rvr {

// `accel` is what answers the queries: the options' for raytrace, Embree for embree.
Expected<std::unique_ptr<PreparedRenderer>> prepare_tracer(const Scene& scene,
                                                           const RenderOptions& options,
                                                           AccelKind accel);

}  // namespace rvr
