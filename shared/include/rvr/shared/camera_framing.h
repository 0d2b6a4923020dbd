// A camera that frames the scene's geometry: for model files without a camera of their own and
// for `--camera-from`, which turns the view without writing JSON.
#pragma once

#include <glm/glm.hpp>

#include "rvr/shared/scene.h"

namespace rvr {

struct BoundingSphere {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
  bool empty = true;
};

// Around every object: mesh vertices, spheres, the corners of plane squares, csg leaves.
BoundingSphere scene_bounds(const Scene& scene);

// The default direction from the model's centre towards the eye: a three-quarter view from
// above, 35 degrees round from +z towards +x and 30 degrees up (y is up).
glm::vec3 default_view_from();

// Puts the camera on the line from the bounding sphere's centre along `from` (any length;
// not zero), looking at the centre with +y up (-z up when looking straight down or up), at the
// distance where the sphere fills the narrower field of view with a 10 % margin; near and far
// enclose the sphere. Keeps fov_y_deg; the image size decides the aspect. No aperture.
void frame_camera(Scene& scene, const BoundingSphere& bounds, glm::vec3 from);

}  // namespace rvr
