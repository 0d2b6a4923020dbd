// The backdrop the compare pictures draw their masks over: a frame's pixel as display-referred
// grey, dimmed so that the masks stand out.
#pragma once

#include <algorithm>
#include <cstddef>
#include <glm/glm.hpp>

#include "rvr/core/framebuffers.h"
#include "rvr/core/srgb.h"
#include "rvr/image_codec/image_io.h"

namespace rvr {

// The sRGB encoding of half of pixel i's linear luminance in `frame` (colour clamped to [0, 1]),
// black where the frame has no such pixel.
inline float dimmed_grey(const FrameBuffers& frame, size_t i) {
  if (i >= frame.colour.size()) return srgb_encode(0.0f);
  const glm::vec3 c = glm::clamp(frame.colour[i], glm::vec3(0.0f), glm::vec3(1.0f));
  return srgb_encode(0.5f * (0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b));
}

// An RGB picture of `frame`'s size: each pixel in the colour `colour_at(i)` gives (three floats,
// display-referred), or where it gives nullptr the frame's dimmed grey.
template <class ColourAt>
Image overlay_on_dimmed(const FrameBuffers& frame, ColourAt colour_at) {
  Image img;
  img.width = frame.width;
  img.height = frame.height;
  img.channels = 3;
  img.channel_names = {"R", "G", "B"};
  const size_t n = frame.pixel_count();
  img.pixels.assign(n * 3, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    float* p = &img.pixels[3 * i];
    if (const float* rgb = colour_at(i)) {
      std::copy(rgb, rgb + 3, p);
      continue;
    }
    p[0] = p[1] = p[2] = dimmed_grey(frame, i);
  }
  return img;
}

}  // namespace rvr
