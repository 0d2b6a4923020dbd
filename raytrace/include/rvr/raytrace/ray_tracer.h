// The CPU ray tracer: "for each pixel, for each object", over a BVH or the plain loop.
#pragma once

#include <string>

#include "rvr/shared/renderer.h"

namespace rvr {

class RayTracer : public Renderer {
 public:
  std::string name() const override { return "raytrace"; }
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options) override;
};

}  // namespace rvr
