// Texture images decoded into mip chains: through the image codec module (read_image), 8-bit
// and 16-bit images taken as sRGB-encoded and decoded to linear, float images (EXR, HDR) as
// linear already, rows flipped so that row 0 is v = 0 (the image's bottom row). Private to
// scene_io/src; only scenes with textures call it, so untextured runs never load the codec.
#pragma once

#include <memory>
#include <string>

#include "mesh_import.h"
#include "rvr/core/expected.h"
#include "rvr/core/texture.h"
#include "rvr/image_codec/image_io.h"

namespace rvr::scene_load {

// Level 0 of a texture from a decoded image (the top row first): RGB from the first three
// channels (grey from the first of one or two), sRGB-decoded when `srgb`, bottom row first.
TextureLevel texture_level(const Image& image, bool srgb);

// Whether the image file holds linear values (by its extension: .exr, .hdr, .pfm) rather than
// sRGB-encoded ones.
bool linear_image_file(const std::string& path);

Expected<std::shared_ptr<const MipChain>> read_texture_file(const std::string& path);
// A model file's own image: compressed bytes go through a temporary file named with their
// format's extension (the codec reads files); raw RGB8 texels are taken as they are.
Expected<std::shared_ptr<const MipChain>> read_embedded_texture(const EmbeddedImage& image);

}  // namespace rvr::scene_load
