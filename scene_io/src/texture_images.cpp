// Texture images to mip chains (texture_images.h).
#include "texture_images.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <glm/glm.hpp>
#include <utility>
#include <vector>

#include "rvr/core/srgb.h"

namespace rvr::scene_load {
namespace {

namespace fs = std::filesystem;

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::shared_ptr<const MipChain> chain_of(TextureLevel level0) {
  return std::make_shared<const MipChain>(build_mip_chain(std::move(level0)));
}

// Raw RGB bytes, the top row first, as an sRGB-encoded image.
TextureLevel rgb8_level(const EmbeddedImage& image) {
  Image decoded;
  decoded.width = image.width;
  decoded.height = image.height;
  decoded.channels = 3;
  decoded.pixels.resize(image.bytes.size());
  for (size_t i = 0; i < image.bytes.size(); ++i) {
    decoded.pixels[i] = float(static_cast<unsigned char>(image.bytes[i])) / 255.0f;
  }
  return texture_level(decoded, true);
}

// Removes the temporary file when it goes out of scope.
struct TemporaryFile {
  std::string path;
  ~TemporaryFile() {
    if (!path.empty()) std::remove(path.c_str());
  }
};

}  // namespace

TextureLevel texture_level(const Image& image, bool srgb) {
  TextureLevel level;
  level.width = image.width;
  level.height = image.height;
  level.texels.resize(size_t(image.width) * size_t(image.height));
  const int c1 = image.channels >= 3 ? 1 : 0, c2 = image.channels >= 3 ? 2 : 0;
  for (int y = 0; y < image.height; ++y) {
    const int row = image.height - 1 - y;  // level row 0 is the image's bottom row
    for (int x = 0; x < image.width; ++x) {
      glm::vec3 c(image.at(x, row, 0), image.at(x, row, c1), image.at(x, row, c2));
      for (int k = 0; k < 3; ++k) {
        if (srgb) {
          c[k] = srgb_decode(c[k]);
        } else if (!std::isfinite(c[k]) || c[k] < 0.0f) {
          c[k] = 0.0f;
        }
      }
      level.texels[size_t(y) * size_t(image.width) + size_t(x)] = c;
    }
  }
  return level;
}

bool linear_image_file(const std::string& path) {
  const std::string ext = lower_extension(path);
  return ext == ".exr" || ext == ".hdr" || ext == ".pfm";
}

Expected<std::shared_ptr<const MipChain>> read_texture_file(const std::string& path) {
  RVR_TRY_ASSIGN(image, read_image(path));
  if (image->channels < 1) return bad_input("cannot read '" + path + "': no channels");
  return chain_of(texture_level(*image, !linear_image_file(path)));
}

Expected<std::shared_ptr<const MipChain>> read_embedded_texture(const EmbeddedImage& image) {
  if (image.format == "rgb8") {
    if (image.width <= 0 || image.height <= 0 ||
        image.bytes.size() != 3 * size_t(image.width) * size_t(image.height)) {
      return bad_input("the embedded image's texels do not match its size");
    }
    return chain_of(rgb8_level(image));
  }
  if (image.bytes.empty()) return bad_input("the embedded image is empty");
  std::string ext;
  for (char c : image.format) {
    if (std::isalnum(static_cast<unsigned char>(c))) ext += c;
  }
  if (ext.empty()) ext = "png";
  std::string name = (fs::temp_directory_path() / ("rvr-texture-XXXXXX." + ext)).string();
  std::vector<char> buffer(name.begin(), name.end());
  buffer.push_back('\0');
  const int fd = ::mkstemps(buffer.data(), int(ext.size() + 1));
  if (fd < 0) return internal_error("cannot make a temporary file for an embedded image");
  TemporaryFile file{buffer.data()};
  bool written = ::write(fd, image.bytes.data(), image.bytes.size()) == ssize_t(image.bytes.size());
  ::close(fd);
  if (!written) return internal_error("cannot write a temporary file for an embedded image");
  Expected<Image> decoded = read_image(file.path);
  if (!decoded) return bad_input(decoded.error().message);
  return chain_of(texture_level(*decoded, !linear_image_file(file.path)));
}

}  // namespace rvr::scene_load
