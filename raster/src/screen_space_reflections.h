// Screen-space reflections: the z-buffer's cheapest answer to a curved mirror. The reflection
// ray is marched across the camera's own frame, one pixel per step, its depth interpolated
// perspective-correctly, until it passes behind what the frame holds: where it crosses the
// stored surface within that step, the frame's colour there is what the mirror shows. What
// the camera does not see cannot be reflected: a ray that leaves the frame (or turns towards the
// camera, behind it) and one that passes behind a surface (its target hidden) are misses, and
// are counted; a ray that stays in front of everything to the end of the scene meets nothing,
// as the tracer's would. One bounce: a hit shows the frame's colour before any reflection.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>

#include "pass_camera.h"
#include "rvr/core/framebuffers.h"

namespace rvr {

enum class SsrOutcome {
  Hit,         // the ray meets a surface the frame holds
  Background,  // it stays in front of everything to the end of the scene: nothing to meet
  OffScreen,   // it leaves the frame, or turns behind the camera, first: a miss
  Hidden,      // it passes behind a surface first: what it meets is hidden, a miss
};

class ScreenSpaceReflections {
 public:
  // `frame`: the camera's colours, depths and ids before any reflection; `reach`: a length
  // past which the scene holds nothing, from anywhere in it; `near`: the camera's near plane.
  ScreenSpaceReflections(const FrameBuffers& frame, const PassCamera& camera, double near,
                         double reach);

  // Marches the ray from p in direction r (unit), leaving the pixels of object `self` (the
  // mirror) behind; on a hit `colour` is the frame's colour there.
  SsrOutcome trace(const glm::dvec3& p, const glm::dvec3& r, uint32_t self,
                   glm::vec3& colour) const;

 private:
  const FrameBuffers& frame_;
  const PassCamera& camera_;
  double near_, reach_;
};

}  // namespace rvr
