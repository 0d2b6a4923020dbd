// The backdrop the compare pictures draw their masks over: a frame's pixel as display-referred
// grey, dimmed so that the masks stand out.
#pragma once

#include <cstddef>
#include <glm/glm.hpp>

#include "rvr/core/framebuffers.h"
#include "rvr/core/srgb.h"

namespace rvr {

// The sRGB encoding of half of pixel i's linear luminance in `frame` (colour clamped to [0, 1]),
// black where the frame has no such pixel.
inline float dimmed_grey(const FrameBuffers& frame, size_t i) {
  if (i >= frame.colour.size()) return srgb_encode(0.0f);
  const glm::vec3 c = glm::clamp(frame.colour[i], glm::vec3(0.0f), glm::vec3(1.0f));
  return srgb_encode(0.5f * (0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b));
}

}  // namespace rvr
