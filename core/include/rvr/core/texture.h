// Base-colour textures: texels and their mip chain, wrap modes, and the one sampling rule every
// renderer uses, OpenGL's LINEAR_MIPMAP_LINEAR. Only the level of detail differs by loop order:
// a z-buffer takes it from screen-space derivatives of the texture coordinates (GL its own,
// softraster exact ones from its plane equations), a tracer from a ray cone or ray
// differentials. The formulas for each are here, so every renderer samples the same texels with
// the same filter and only its level of detail is its own.
#pragma once

#include <stddef.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

namespace rvr {

enum class TextureWrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };

// How the tracer chooses a level of detail (RenderOptions::texture_lod).
enum class TextureLod : uint8_t {
  Cones,          // ray cones (Akenine-Moller et al., Ray Tracing Gems ch. 20, 2019)
  Differentials,  // ray differentials (Igehy 1999)
  None,           // level 0 only (bilinear)
};

// One level: linear RGB texels, row by row from v = 0 (the image's bottom row) up, as OpenGL
// stores a texture.
struct TextureLevel {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> texels;

  const glm::vec3& at(int x, int y) const { return texels[size_t(y) * size_t(width) + size_t(x)]; }
};

// Level 0 and its reductions down to 1x1: level k+1 is max(1, w/2) x max(1, h/2) (sizes rounded
// down, as GL's), each texel the mean of the 2x2 texels of level k it covers (the last row or
// column of an odd size folded into its neighbour's mean, 2x3, 3x2 or 3x3 texels). Every
// renderer samples (GL is given) these very levels, so the texels filtered are the same.
struct MipChain {
  std::vector<TextureLevel> levels;

  int width() const { return levels.empty() ? 0 : levels[0].width; }
  int height() const { return levels.empty() ? 0 : levels[0].height; }
  float max_lod() const { return float(levels.size()) - 1.0f; }
};

MipChain build_mip_chain(TextureLevel level0);

struct Texture {
  std::string file;      // as the scene or model file names it
  std::string resolved;  // the file read; empty for a texture made in memory or not found
  TextureWrap wrap_u = TextureWrap::Repeat;
  TextureWrap wrap_v = TextureWrap::Repeat;
  // Null when the file could not be read: the scene carries a warning naming it, and the
  // materials that use it render with their base colour alone.
  std::shared_ptr<const MipChain> mips;
};

// GL's LINEAR on one level: the four texels around uv * size - 0.5 (texel centres at
// (i + 0.5) / size), each index wrapped on its own axis, weighted bilinearly.
glm::vec3 sample_bilinear(const TextureLevel& level, TextureWrap wrap_u, TextureWrap wrap_v,
                          glm::vec2 uv);

// GL's LINEAR_MIPMAP_LINEAR: lod clamped to [0, max_lod]; levels floor(lod) and the next
// blended by the fraction. A NaN lod samples level 0.
glm::vec3 sample_trilinear(const MipChain& mips, TextureWrap wrap_u, TextureWrap wrap_v,
                           glm::vec2 uv, float lod);

inline glm::vec3 sample_texture(const Texture& t, glm::vec2 uv, float lod) {
  return t.mips ? sample_trilinear(*t.mips, t.wrap_u, t.wrap_v, uv, lod) : glm::vec3(1.0f);
}

// The level of detail of the GL specification (4.6, section 8.14.1, equations 8.7-8.9, the
// exact form): rho = max(|d(uv * size)/dx|, |d(uv * size)/dy|), lambda = log2(rho); duv_dx and
// duv_dy are the texture coordinates' derivatives per pixel along x and y. -inf when rho is 0.
float lod_from_derivatives(glm::vec2 duv_dx, glm::vec2 duv_dy, int width, int height);

// Ray cones (Ray Tracing Gems ch. 20, eq. 34): the triangle's constant
// delta = 0.5 log2(texel area / world area), texel area = width * height * (uv area), and at a
// hit lambda = delta + log2(|cone width| / |cos theta|), theta the angle between the ray and
// the surface normal. A cone's width at distance t is spread_angle * t for a primary ray
// (spread_angle = atan(2 tan(fov_y / 2) / image height), eq. 30).
float triangle_lod_constant(float world_area, float uv_area, int width, int height);
float lod_from_cone(float triangle_constant, float cone_width, float cos_theta);
float primary_cone_spread(float fov_y_radians, int image_height);

}  // namespace rvr
