// A scene loaded as a render needs it: the instruction set checked, the scene (file, model or
// built-in) loaded with the caller's overrides, the sample count replaced, the resource limits
// checked. The command line and the Python module load through this one function.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "rvr/core/expected.h"
#include "rvr/core/limits.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/scene_io/scene_loader.h"

namespace rvr {

struct SceneRequest {
  std::string spec = "builtin:cornell";  // a scene file, a model file or builtin:NAME
  // A scene from memory (JSON text: load_scene_text; a mesh: load_mesh_scene) loaded by this
  // instead of `spec`, which then names it; given the overrides.
  std::function<Expected<Scene>(const SceneOverrides&)> load;
  SceneOverrides overrides;
  std::optional<int> spp;  // replaces image.samples_per_pixel
  Limits limits;
};

// Errors are bad input (a bad RVR_ISA, the loader's "FILE: json.path: what is wrong", a limit
// passed). `load_seconds`, when given, receives the time spent loading the scene.
Expected<Scene> load_scene_for_render(const SceneRequest& request, const RenderOptions& options,
                                      double* load_seconds = nullptr);

}  // namespace rvr
