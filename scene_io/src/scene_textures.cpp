// A loading scene's textures (scene_textures.h).
#include "scene_textures.h"

#include <fmt/format.h>
#include <stddef.h>

#include <cstdint>
#include <utility>

#include "rvr/core/expected.h"
#include "scene_json_errors.h"
#include "texture_images.h"
#include "texture_paths.h"

namespace rvr::scene_load {
namespace {

// What read_image says after "cannot read 'PATH': ", the reason alone.
std::string reason_of(const std::string& message) {
  const size_t at = message.find("': ");
  return at == std::string::npos ? message : message.substr(at + 3);
}

// "*N" with N a valid index into `images`, else -1.
long embedded_index(const std::string& file, const std::vector<EmbeddedImage>* images) {
  if (!images || file.size() < 2 || file[0] != '*') return -1;
  if (file.find_first_not_of("0123456789", 1) != std::string::npos || file.size() > 10) return -1;
  const long n = std::stol(file.substr(1));
  return size_t(n) < images->size() ? n : -1;
}

}  // namespace

const SceneTextures::Image& SceneTextures::image(const std::string& file, const std::string& folder,
                                                 const std::vector<EmbeddedImage>* images,
                                                 const std::string& label, std::string* key) {
  const long embedded = embedded_index(file, images);
  const std::string resolved = embedded >= 0 ? std::string() : find_texture_file(file, folder);
  // An embedded image by its contents (models of one scene may share it, and the same "*N" of
  // two models is two images); a missing file by its name where it was looked for.
  if (embedded >= 0) {
    const EmbeddedImage& e = (*images)[size_t(embedded)];
    *key = fmt::format("*{}\n{}\n{}x{}\n{}", e.format, e.bytes.size(), e.width, e.height,
                       std::hash<std::string>{}(e.bytes));
  } else {
    *key = resolved.empty() ? "?" + folder + "\n" + file : resolved;
  }
  auto [it, added] = images_.try_emplace(*key);
  Image& image = it->second;
  if (!added) return image;
  image.resolved = resolved;
  if (embedded >= 0) {
    const EmbeddedImage& e = (*images)[size_t(embedded)];
    Expected<std::shared_ptr<const MipChain>> mips = read_embedded_texture(e);
    if (mips) {
      image.mips = *mips;
    } else {
      warnings_.push_back(
          fmt::format("{}: cannot read the embedded texture {} ({}): rendered "
                      "without it",
                      label, quote_json(e.name), reason_of(mips.error().message)));
    }
  } else if (resolved.empty()) {
    const std::string parent = texture_search_parent(folder);
    warnings_.push_back(fmt::format(
        "{}: texture {} not found (looked in {}{} and {} subfolders): rendered without it", label,
        quote_path(file), quote_path(folder.empty() ? std::string(".") : folder),
        parent.empty() ? "" : ", " + quote_path(parent), parent.empty() ? "its" : "their"));
  } else {
    Expected<std::shared_ptr<const MipChain>> mips = read_texture_file(resolved);
    if (mips) {
      image.mips = *mips;
    } else {
      warnings_.push_back(fmt::format("{}: cannot read texture {} at {} ({}): rendered without it",
                                      label, quote_path(file), quote_path(resolved),
                                      reason_of(mips.error().message)));
    }
  }
  return image;
}

int32_t SceneTextures::add(const std::string& file, const std::string& folder, TextureWrap wrap_u,
                           TextureWrap wrap_v, const std::vector<EmbeddedImage>* images,
                           const std::string& label) {
  std::string key;
  const Image& found = image(file, folder, images, label, &key);
  auto [it, added] = textures_.try_emplace({key, wrap_u, wrap_v}, 0);
  if (!added) return it->second;
  Texture t;
  t.file = file;
  t.resolved = found.resolved;
  t.wrap_u = wrap_u;
  t.wrap_v = wrap_v;
  t.mips = found.mips;
  scene_.textures.push_back(std::move(t));
  it->second = int32_t(scene_.textures.size() - 1);
  return it->second;
}

}  // namespace rvr::scene_load
