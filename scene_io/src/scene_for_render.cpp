#include "rvr/scene_io/scene_for_render.h"

#include <chrono>
#include <variant>

#include "rvr/core/isa.h"
#include "rvr/core/timer.h"

namespace rvr {

Expected<Scene> load_scene_for_render(const SceneRequest& request, const RenderOptions& options,
                                      double* load_seconds) {
  // A bad RVR_ISA is refused before any work.
  if (Expected<Isa> isa = selected_isa(); !isa) return isa.error();
  const auto start = std::chrono::steady_clock::now();
  RVR_TRY_ASSIGN(scene, request.load ? request.load(request.overrides)
                                     : load_scene(request.spec, request.overrides));
  if (request.spp) scene->image.samples_per_pixel = *request.spp;
  if (load_seconds) *load_seconds = seconds_since(start);
  RVR_TRY(check_limits(*scene, options, request.limits));
  return scene;
}

}  // namespace rvr
