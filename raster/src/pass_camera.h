// The camera a z-buffer's frame was drawn through (the scene's, or one accumulation-buffer
// sample's), for the passes that work on the frame afterwards: each pixel's ray and the point
// at its depth, and where a world point lands on screen.
#pragma once

#include <glm/glm.hpp>

#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr {

// The camera's ray through a pixel centre: unit direction, and the point at a given view depth.
struct PixelRay {
  glm::dvec3 direction;
  glm::dvec3 at_depth;
};

struct PassCamera {
  glm::dmat4 view{1.0}, projection{1.0}, unproject{1.0};
  int width = 0, height = 0;

  // Pixel (x, y)'s ray: the line between the points its centre unprojects to at the near and
  // far planes (with an image sample, the ray from its lens point through its place in the
  // pixel), and its point at view depth `depth` (view depth is affine along a line).
  PixelRay ray(int x, int y, double depth) const;

  // p in clip space (before the division by w).
  glm::dvec4 clip(const glm::dvec3& p) const { return projection * (view * glm::dvec4(p, 1.0)); }

  // The view depth of p (distance along the view axis).
  double depth(const glm::dvec3& p) const { return -(view * glm::dvec4(p, 1.0)).z; }
};

// The camera `scene` is drawn through with `options` (its image_sample, if any).
PassCamera pass_camera(const Scene& scene, const RenderOptions& options);

}  // namespace rvr
