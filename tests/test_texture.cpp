// rvr/core/texture.h against closed forms worked out here: the mip chain's box reductions (odd
// sizes too), GL's LINEAR and LINEAR_MIPMAP_LINEAR at texel centres and half-way between them,
// the three wrap modes outside [0, 1], the GL specification's level of detail for known
// derivatives, the ray-cone formulas on a square of known size, and KHR_texture_transform's
// matrix written out as the extension's GLSL.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <initializer_list>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "rvr/core/scene.h"
#include "rvr/core/texture.h"

namespace {

using rvr::TextureWrap;

// A level whose texel (x, y) is grey with the value `value(x, y)`.
template <class F>
rvr::TextureLevel grey_level(int w, int h, F value) {
  rvr::TextureLevel level;
  level.width = w;
  level.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) level.texels.push_back(glm::vec3(value(x, y)));
  return level;
}

// Distinct, irregular texel values, so that averaging the wrong texels shows.
float irregular(int x, int y) {
  return float((x * 7 + y * 13 + x * y * 3) % 17) + 0.25f * float(x);
}

void expect_vec3(const glm::vec3& got, float want, float tolerance = 1e-6f) {
  EXPECT_NEAR(got.x, want, tolerance);
  EXPECT_NEAR(got.y, want, tolerance);
  EXPECT_NEAR(got.z, want, tolerance);
}

TEST(MipChain, EvenLevelsAreTheMeansOfTwoByTwoBlocks) {
  const rvr::MipChain chain = rvr::build_mip_chain(grey_level(8, 4, irregular));
  ASSERT_EQ(chain.levels.size(), 4u);  // 8x4, 4x2, 2x1, 1x1
  EXPECT_EQ(chain.levels[1].width, 4);
  EXPECT_EQ(chain.levels[1].height, 2);
  EXPECT_EQ(chain.levels[3].width, 1);
  EXPECT_EQ(chain.levels[3].height, 1);
  EXPECT_FLOAT_EQ(chain.max_lod(), 3.0f);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      const float mean = (irregular(2 * x, 2 * y) + irregular(2 * x + 1, 2 * y) +
                          irregular(2 * x, 2 * y + 1) + irregular(2 * x + 1, 2 * y + 1)) /
                         4.0f;
      expect_vec3(chain.levels[1].at(x, y), mean, 1e-5f);
    }
  float total = 0.0f;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) total += irregular(x, y);
  // A power-of-two chain's last level is the mean of every texel.
  expect_vec3(chain.levels[3].at(0, 0), total / 32.0f, 1e-4f);
}

TEST(MipChain, OddSizesFoldTheLeftoverRowAndColumnIntoTheLastMean) {
  // 5x3 -> 2x1 (texel 0: columns 0-1, texel 1: columns 2-4; rows 0-2 both) -> 1x1.
  const rvr::MipChain chain = rvr::build_mip_chain(grey_level(5, 3, irregular));
  ASSERT_EQ(chain.levels.size(), 3u);
  ASSERT_EQ(chain.levels[1].width, 2);
  ASSERT_EQ(chain.levels[1].height, 1);
  float left = 0.0f, right = 0.0f;
  for (int y = 0; y < 3; ++y) {
    left += irregular(0, y) + irregular(1, y);
    right += irregular(2, y) + irregular(3, y) + irregular(4, y);
  }
  expect_vec3(chain.levels[1].at(0, 0), left / 6.0f, 1e-5f);
  expect_vec3(chain.levels[1].at(1, 0), right / 9.0f, 1e-5f);
  expect_vec3(chain.levels[2].at(0, 0), (left / 6.0f + right / 9.0f) / 2.0f, 1e-5f);
}

TEST(MipChain, OneTexelWideStaysOneWide) {
  // 1x4 -> 1x2 -> 1x1: only the rows are averaged.
  const rvr::MipChain chain = rvr::build_mip_chain(grey_level(1, 4, irregular));
  ASSERT_EQ(chain.levels.size(), 3u);
  EXPECT_EQ(chain.levels[1].width, 1);
  expect_vec3(chain.levels[1].at(0, 1), (irregular(0, 2) + irregular(0, 3)) / 2.0f, 1e-5f);
}

TEST(SampleBilinear, TexelCentresReturnTheTexelExactly) {
  const rvr::TextureLevel level = grey_level(8, 4, irregular);
  for (TextureWrap wrap :
       {TextureWrap::Repeat, TextureWrap::ClampToEdge, TextureWrap::MirroredRepeat})
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 8; ++x) {
        const glm::vec2 centre((float(x) + 0.5f) / 8.0f, (float(y) + 0.5f) / 4.0f);
        EXPECT_EQ(rvr::sample_bilinear(level, wrap, wrap, centre), level.at(x, y)) << x << "," << y;
      }
}

TEST(SampleBilinear, HalfWayBetweenTexelsIsTheirMean) {
  const rvr::TextureLevel level = grey_level(8, 4, irregular);
  const auto r = TextureWrap::Repeat;
  // Between the centres of texels (2, 1) and (3, 1): u = 3/8.
  expect_vec3(rvr::sample_bilinear(level, r, r, {3.0f / 8.0f, 1.5f / 4.0f}),
              (irregular(2, 1) + irregular(3, 1)) / 2.0f);
  // Between (5, 1) and (5, 2) along v: v = 2/4.
  expect_vec3(rvr::sample_bilinear(level, r, r, {5.5f / 8.0f, 0.5f}),
              (irregular(5, 1) + irregular(5, 2)) / 2.0f);
  // The corner shared by four texels: their mean.
  expect_vec3(rvr::sample_bilinear(level, r, r, {0.5f, 0.5f}),
              (irregular(3, 1) + irregular(4, 1) + irregular(3, 2) + irregular(4, 2)) / 4.0f,
              1e-5f);
  // A quarter of the way: weights 3/4 and 1/4.
  expect_vec3(rvr::sample_bilinear(level, r, r, {(2.5f + 0.25f) / 8.0f, 1.5f / 4.0f}),
              0.75f * irregular(2, 1) + 0.25f * irregular(3, 1), 1e-5f);
}

// One row of four texels valued 0, 1, 2, 3, sampled at u (v at the row's centre).
float row_sample(TextureWrap wrap, float u) {
  static const rvr::TextureLevel row = grey_level(4, 1, [](int x, int) { return float(x); });
  return rvr::sample_bilinear(row, wrap, TextureWrap::Repeat, {u, 0.5f}).x;
}

TEST(SampleBilinear, RepeatWrapsBothTheCoordinateAndTheNeighbour) {
  const auto w = TextureWrap::Repeat;
  EXPECT_FLOAT_EQ(row_sample(w, 1.125f), 0.0f);   // texel 0's centre one period on
  EXPECT_FLOAT_EQ(row_sample(w, -0.125f), 3.0f);  // texel 3's centre one period back
  EXPECT_FLOAT_EQ(row_sample(w, 7.375f), 1.0f);   // seven periods on
  EXPECT_FLOAT_EQ(row_sample(w, 0.0f), 1.5f);     // half-way between texels 3 and 0
  EXPECT_FLOAT_EQ(row_sample(w, 2.0f), 1.5f);
}

TEST(SampleBilinear, ClampToEdgeHoldsTheEdgeTexels) {
  const auto w = TextureWrap::ClampToEdge;
  EXPECT_FLOAT_EQ(row_sample(w, 1.5f), 3.0f);
  EXPECT_FLOAT_EQ(row_sample(w, -0.7f), 0.0f);
  EXPECT_FLOAT_EQ(row_sample(w, 0.0f), 0.0f);  // the edge itself: no neighbour across it
  EXPECT_FLOAT_EQ(row_sample(w, 1.0f), 3.0f);
}

TEST(SampleBilinear, MirroredRepeatReflectsEveryOtherPeriod) {
  const auto w = TextureWrap::MirroredRepeat;
  EXPECT_FLOAT_EQ(row_sample(w, 1.125f), 3.0f);   // mirrored: 2 - 1.125 = 0.875, texel 3
  EXPECT_FLOAT_EQ(row_sample(w, 1.375f), 2.0f);   // 0.625, texel 2
  EXPECT_FLOAT_EQ(row_sample(w, -0.125f), 0.0f);  // mirrored: 0.125, texel 0
  EXPECT_FLOAT_EQ(row_sample(w, -0.375f), 1.0f);
  EXPECT_FLOAT_EQ(row_sample(w, 2.125f), 0.0f);  // two periods: as 0.125
  EXPECT_FLOAT_EQ(row_sample(w, 1.0f), 3.0f);    // the mirror's edge: texel 3 and itself
}

TEST(SampleTrilinear, BlendsTwoLevelsByTheFractionAndClampsTheLod) {
  // 2x2 -> 1x1. At texel (0, 0)'s centre, level 0 gives it and level 1 the mean of all four.
  const rvr::MipChain chain = rvr::build_mip_chain(grey_level(2, 2, irregular));
  const float t00 = irregular(0, 0);
  const float mean = (irregular(0, 0) + irregular(1, 0) + irregular(0, 1) + irregular(1, 1)) / 4;
  const auto r = TextureWrap::Repeat;
  const glm::vec2 uv(0.25f, 0.25f);
  expect_vec3(rvr::sample_trilinear(chain, r, r, uv, 0.0f), t00);
  expect_vec3(rvr::sample_trilinear(chain, r, r, uv, 0.5f), 0.5f * (t00 + mean), 1e-5f);
  expect_vec3(rvr::sample_trilinear(chain, r, r, uv, 0.25f), 0.75f * t00 + 0.25f * mean, 1e-5f);
  expect_vec3(rvr::sample_trilinear(chain, r, r, uv, 1.0f), mean, 1e-5f);
  expect_vec3(rvr::sample_trilinear(chain, r, r, uv, -3.0f), t00);         // below 0: level 0
  expect_vec3(rvr::sample_trilinear(chain, r, r, uv, 9.0f), mean, 1e-5f);  // above max_lod
  expect_vec3(rvr::sample_trilinear(chain, r, r, uv, -std::numeric_limits<float>::infinity()), t00);
  expect_vec3(rvr::sample_trilinear(chain, r, r, uv, std::nanf("")), t00);
}

TEST(LodFromDerivatives, IsLog2OfTheLongerTexelFootprint) {
  // One texel per pixel on a 256x256 texture: level 0; four: level 2.
  EXPECT_FLOAT_EQ(rvr::lod_from_derivatives({1.0f / 256, 0}, {0, 1.0f / 256}, 256, 256), 0.0f);
  EXPECT_FLOAT_EQ(rvr::lod_from_derivatives({4.0f / 256, 0}, {0, 4.0f / 256}, 256, 256), 2.0f);
  // Anisotropic: the longer of the two footprints decides.
  EXPECT_FLOAT_EQ(rvr::lod_from_derivatives({4.0f / 256, 0}, {0, 1.0f / 256}, 256, 256), 2.0f);
  EXPECT_FLOAT_EQ(rvr::lod_from_derivatives({1.0f / 256, 0}, {0, 8.0f / 256}, 256, 256), 3.0f);
  // Each axis scaled by its own size: 2 texels along v of a 512x128 texture.
  EXPECT_FLOAT_EQ(rvr::lod_from_derivatives({1.0f / 512, 0}, {0, 2.0f / 128}, 512, 128), 1.0f);
  // The exact form (a vector's length, not the sum or the larger of its components): a 3-4-5
  // footprint has rho = 5.
  EXPECT_NEAR(rvr::lod_from_derivatives({3.0f / 256, 4.0f / 256}, {0, 1.0f / 256}, 256, 256),
              std::log2(5.0f), 1e-6f);
  // Magnification: half a texel per pixel, level -1 (the sampler clamps it to 0).
  EXPECT_FLOAT_EQ(rvr::lod_from_derivatives({0.5f / 256, 0}, {0, 0.5f / 256}, 256, 256), -1.0f);
  EXPECT_EQ(rvr::lod_from_derivatives({0, 0}, {0, 0}, 256, 256),
            -std::numeric_limits<float>::infinity());
}

TEST(RayCones, TriangleConstantAndLodOnAKnownSquare) {
  // Half of a 2x2 world square mapped to the whole [0,1]^2 of a 256x256 texture: world area 2,
  // uv area 1/2, texel area 256^2 / 2; delta = 0.5 log2(32768 / 2) = 7.
  const float delta = rvr::triangle_lod_constant(2.0f, 0.5f, 256, 256);
  EXPECT_FLOAT_EQ(delta, 7.0f);
  EXPECT_FLOAT_EQ(rvr::triangle_lod_constant(2.0f, -0.5f, 256, 256), 7.0f);  // either winding
  // A cone 1/128 wide met head-on covers one texel (128 texels per world unit): level 0.
  EXPECT_FLOAT_EQ(rvr::lod_from_cone(delta, 1.0f / 128.0f, 1.0f), 0.0f);
  // 60 degrees from the normal the footprint doubles: level 1.
  EXPECT_NEAR(rvr::lod_from_cone(delta, 1.0f / 128.0f, 0.5f), 1.0f, 1e-6f);
  EXPECT_NEAR(rvr::lod_from_cone(delta, 1.0f / 128.0f, -0.5f), 1.0f, 1e-6f);  // back face
  EXPECT_FLOAT_EQ(rvr::lod_from_cone(delta, 4.0f / 128.0f, 1.0f), 2.0f);
  // Degenerate triangles have no level.
  EXPECT_EQ(rvr::triangle_lod_constant(0.0f, 0.5f, 256, 256),
            -std::numeric_limits<float>::infinity());
  // A 90 degree field of view over 2 rows: tan(45) = 1, spread atan(2 * 1 / 2) = pi / 4.
  EXPECT_NEAR(rvr::primary_cone_spread(float(std::numbers::pi / 2), 2), float(std::numbers::pi / 4),
              1e-6f);
  // Over 512 rows at 60 degrees: atan(2 tan(30 deg) / 512).
  EXPECT_NEAR(rvr::primary_cone_spread(float(std::numbers::pi / 3), 512),
              std::atan(2.0 * std::tan(std::numbers::pi / 6) / 512.0), 1e-9);
}

// KHR_texture_transform as its specification writes it in GLSL (column-major mat3, which glm
// shares), in glTF's v-down texture space: s = (u, 1 - v).
glm::vec2 khr_transform(glm::vec2 offset, float rotation, glm::vec2 scale, glm::vec2 uv) {
  const float c = std::cos(rotation), s = std::sin(rotation);
  const glm::mat3 translation(1, 0, 0, 0, 1, 0, offset.x, offset.y, 1);
  const glm::mat3 rotate(c, s, 0, -s, c, 0, 0, 0, 1);
  const glm::mat3 scaling(scale.x, 0, 0, 0, scale.y, 0, 0, 0, 1);
  const glm::vec3 t = translation * rotate * scaling * glm::vec3(uv.x, 1.0f - uv.y, 1.0f);
  return {t.x, 1.0f - t.y};
}

TEST(UvTransform, MatchesTheExtensionsMatrix) {
  rvr::UvTransform identity;
  EXPECT_TRUE(identity.identity());
  EXPECT_EQ(identity.apply({0.3f, 0.7f}), glm::vec2(0.3f, 0.7f));

  rvr::UvTransform t;
  t.offset = {0.5f, -0.25f};
  t.rotation = 0.392699f;  // 22.5 degrees, as glTF's TextureTransformTest sample
  t.scale = {1.5f, 0.75f};
  EXPECT_FALSE(t.identity());
  for (glm::vec2 uv : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(0, 1), glm::vec2(0.3f, 0.8f),
                       glm::vec2(-2.5f, 3.25f)}) {
    const glm::vec2 want = khr_transform(t.offset, t.rotation, t.scale, uv);
    const glm::vec2 got = t.apply(uv);
    EXPECT_NEAR(got.x, want.x, 1e-5f) << uv.x << "," << uv.y;
    EXPECT_NEAR(got.y, want.y, 1e-5f) << uv.x << "," << uv.y;
  }
  // One case by hand: a quarter turn of glTF's s = (1, 0) (uv (1, 1)) is (0, 1), uv (0, 0).
  rvr::UvTransform quarter;
  quarter.rotation = float(std::numbers::pi / 2);
  const glm::vec2 q = quarter.apply({1.0f, 1.0f});
  EXPECT_NEAR(q.x, 0.0f, 1e-6f);
  EXPECT_NEAR(q.y, 0.0f, 1e-6f);
  // Offset alone, in glTF's v-down space: offset (0.25, 0.5) moves uv (0, 1) to (0.25, 0.5).
  rvr::UvTransform shift;
  shift.offset = {0.25f, 0.5f};
  const glm::vec2 o = shift.apply({0.0f, 1.0f});
  EXPECT_FLOAT_EQ(o.x, 0.25f);
  EXPECT_FLOAT_EQ(o.y, 0.5f);
}

}  // namespace
