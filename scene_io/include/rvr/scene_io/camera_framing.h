// A camera that frames the scene's geometry: for model files without a camera of their own and
// for `--camera-from`, which turns the view without writing JSON.
#pragma once

#include <glm/glm.hpp>

#include "rvr/core/scene.h"

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

// How a camera shows the scene's triangles (spheres, planes and CSG are not counted), the
// measure by which a model file's own camera is judged (docs/scene-format.md, "Model files as
// scenes"). kViewSamples points are spread over the triangles in proportion to their area
// (point k at (k + 1/2) / kViewSamples of the running total of area, placed inside its
// triangle by a fixed low-discrepancy sequence), so every run judges alike.
struct ViewOfModel {
  // The share of the points inside the camera's view volume: between near and far along the
  // view axis and inside the four side planes of the field of view (`aspect` = width / height).
  float seen = 0.0f;
  // How large the points seen are in the frame: the larger of the width and the height of the
  // rectangle round their projections, each as a share of the frame's (0 when none is seen).
  float size = 0.0f;
};
constexpr int kViewSamples = 4096;
ViewOfModel view_of_model(const Scene& scene, const Camera& camera, float aspect);

// A model file's camera frames the model when it sees at least kMinSeen of it and shows what it
// sees at least kMinSize of the frame across; otherwise the framing camera replaces it.
constexpr float kMinSeen = 0.95f;
constexpr float kMinSize = 0.1f;

}  // namespace rvr
