// Where a box can appear on screen: the pixels whose centre rays may meet it.
#pragma once

#include "rvr/core/camera.h"
#include "rvr/raytrace/bvh.h"

namespace rvr {

// Pixels [x0, x1) x [y0, y1); empty when x0 >= x1 or y0 >= y1.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
};

// A conservative bound of the pixels whose centre rays (from the eye, view depth above `near`)
// can meet `box`: the projection of its corners, widened by two pixels against rounding; the
// whole image when a corner lies nearer than `near` (the box may wrap around the eye).
PixelRect screen_bounds(const CameraFrame& frame, float near, const Aabb& box);

}  // namespace rvr
