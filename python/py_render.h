// A finished render as Python holds it (rvr.Render): the frame buffers with the scene and the
// settings they came from, shared with the numpy arrays made over them.
#pragma once

#include <memory>
#include <string>

#include "render_stats.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr::python {

struct RenderResult {
  std::string renderer;
  std::shared_ptr<const Scene> scene;
  RenderMode mode = RenderMode::Local;
  // How spheres were drawn (spheres=, sphere_segments=): rvr.compare classes depth outliers
  // on analytic spheres with them, as rvr compare does.
  SphereMode spheres = SphereMode::Analytic;
  int sphere_segments = 0;
  RenderTimes times;
  RenderOutput output;
  std::string stats_json;  // the --stats document, made when the render finished
};

struct PyRender {
  std::shared_ptr<const RenderResult> result;
};

}  // namespace rvr::python
