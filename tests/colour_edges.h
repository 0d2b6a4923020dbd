// Colour comparisons for tests that hold a z-buffer's effect to the tracer's pixel by pixel:
// the largest channel difference, and whether a pixel lies beside an edge of what an image
// shows (where a tie or a filtered lookup may fall on either side).
#pragma once

#include <algorithm>
#include <cstddef>
#include <glm/glm.hpp>

#include "rvr/core/framebuffers.h"

namespace rvr::test {

// The largest channel difference of pixel i's colours in `a` and `b`.
inline float colour_difference(const FrameBuffers& a, const FrameBuffers& b, size_t i) {
  const glm::vec3 d = glm::abs(a.colour[i] - b.colour[i]);
  return std::max({d.x, d.y, d.z});
}

// Whether pixel (x, y) of `fb` has a neighbour (of the eight) whose colour differs from its own
// by more than `same` in some channel.
inline bool beside_an_edge(const FrameBuffers& fb, int x, int y, float same) {
  const size_t i = size_t(y) * size_t(fb.width) + size_t(x);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= fb.width || ny >= fb.height) continue;
      const size_t j = size_t(ny) * size_t(fb.width) + size_t(nx);
      const glm::vec3 d = glm::abs(fb.colour[i] - fb.colour[j]);
      if (std::max({d.x, d.y, d.z}) > same) return true;
    }
  return false;
}

}  // namespace rvr::test
