// The sRGB transfer function, from linear values to display-referred ones (8-bit images, the
// display-referred greys of the report) and back (8-bit textures).
#pragma once

#include <cstdint>

namespace rvr {

// Linear [0, 1] to sRGB-encoded [0, 1]; below 0 and NaN give 0, above 1 gives 1.
float srgb_encode(float linear);

// sRGB-encoded [0, 1] to linear [0, 1] (IEC 61966-2-1: c / 12.92 up to 0.04045, else
// ((c + 0.055) / 1.055)^2.4); below 0 and NaN give 0, above 1 gives 1.
float srgb_decode(float encoded);

// The 8-bit value of a linear one, exactly lround(255 * srgb_encode(linear)) for every float,
// found in a table of the 255 places where that value steps (no pow per pixel).
uint8_t srgb8(float linear);

}  // namespace rvr
