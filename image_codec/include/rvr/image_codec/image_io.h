// Image files through OpenImageIO. Every write goes to a temporary name in the same folder
// and is renamed into place, so a failed run never leaves a half-written file.
#pragma once

#include <stddef.h>

#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"

namespace rvr {

// Float pixels, interleaved, y = 0 the TOP row.
struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<std::string> channel_names;  // optional; written to EXR
  std::vector<float> pixels;

  float& at(int x, int y, int c) { return pixels[(size_t(y) * width + x) * channels + c]; }
  float at(int x, int y, int c) const { return pixels[(size_t(y) * width + x) * channels + c]; }
};

// Writes by extension: .png (8-bit, sRGB transfer applied to linear values, clamped),
// .exr (float, linear), anything else OpenImageIO writes. Creates missing folders.
// `linear_to_srgb` false writes the values as they are (already display-referred, e.g. heat maps).
Status write_image(const std::string& path, const Image& image, bool linear_to_srgb = true);

// Reads any format OpenImageIO reads; values as float (8-bit PNG comes back as 0..1 as stored).
Expected<Image> read_image(const std::string& path);

// Linear colour of a render as a 3-channel image.
Image colour_image(const FrameBuffers& fb);

// The cost AOV on the inferno colour map (display-referred). `scale`, the cost at the top of
// the map, is the 99th percentile of the non-zero costs (at least 1) and is returned too.
Image cost_image(const FrameBuffers& fb, float* scale = nullptr);

// Writes the AOVs named in `aovs` ("depth", "id", "normal", "cost", "lod") beside `out_path`:
// OUT.depth.exr, OUT.id.exr (channels id, prim; background -1), OUT.normal.exr,
// OUT.cost.exr and a colour-mapped OUT.cost.png, OUT.lod.exr (the texture level of detail
// sampled, NaN where the surface is not textured). OUT is out_path without its extension.
Status write_aovs(const std::string& out_path, const FrameBuffers& fb,
                  const std::vector<std::string>& aovs);

// OpenImageIO's version, for `rvr info`.
std::string openimageio_version();

// Deletes the temporary file of a write in progress, if any. Async-signal-safe: for a SIGINT
// handler, so an interrupted run leaves no half-written file behind.
void remove_unfinished_output() noexcept;

// Writes `text` to `path` atomically (temporary name, then rename); creates missing folders.
Status write_text_file(const std::string& path, const std::string& text);

}  // namespace rvr
