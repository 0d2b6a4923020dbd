// The textures of a scene being loaded: each texture a material names found (texture_paths.h),
// decoded once (texture_images.h) and added to Scene::textures. A texture that cannot be found
// or read is a warning naming it, never an error: it stays in Scene::textures with no texels,
// and the materials that use it render with their colour alone. Private to scene_io/src.
#pragma once

#include <stdint.h>

#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "mesh_import.h"
#include "rvr/core/scene.h"
#include "rvr/core/texture.h"

namespace rvr::scene_load {

class SceneTextures {
 public:
  // Textures go to scene.textures, warnings to `warnings`.
  SceneTextures(Scene& scene, std::vector<std::string>& warnings)
      : scene_(scene), warnings_(warnings) {}

  // The index in Scene::textures of `file` (as the model or scene file writes it; "*N" is
  // images[N] when `images` is given) looked for from `folder`, with these wrap modes.
  // `label` starts the warning when it cannot be found or read.
  int32_t add(const std::string& file, const std::string& folder, TextureWrap wrap_u,
              TextureWrap wrap_v, const std::vector<EmbeddedImage>* images,
              const std::string& label);

 private:
  struct Image {
    std::string resolved;
    std::shared_ptr<const MipChain> mips;
  };
  const Image& image(const std::string& file, const std::string& folder,
                     const std::vector<EmbeddedImage>* images, const std::string& label,
                     std::string* key);

  Scene& scene_;
  std::vector<std::string>& warnings_;
  // Images by where they come from (a resolved path, or the file and "*N"), and textures by
  // that and their wrap modes.
  std::map<std::string, Image> images_;
  std::map<std::tuple<std::string, TextureWrap, TextureWrap>, int32_t> textures_;
};

}  // namespace rvr::scene_load
