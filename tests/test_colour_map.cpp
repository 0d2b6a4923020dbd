// rvr's inferno colour map (image_codec/src/image_io.cpp: the cost pictures, the heat maps of
// compare) against OpenImageIO's ImageBufAlgo::color_map(..., "inferno"): the same values must
// give the same colours, bit for bit. This test links OpenImageIO itself as the oracle; rvr
// computes the map without loading it.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/typedesc.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <glm/glm.hpp>
#include <initializer_list>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rvr/core/check.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/srgb.h"
#include "rvr/image_codec/image_io.h"

using namespace rvr;

namespace {

// OpenImageIO's inferno of each value, as rvr writes it: display referred (sRGB-encoded).
std::vector<float> library_inferno(const std::vector<float>& values) {
  const int n = int(values.size());
  OIIO::ImageBuf src(OIIO::ImageSpec(n, 1, 1, OIIO::TypeDesc::FLOAT));
  src.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, values.data());
  OIIO::ImageBuf mapped = OIIO::ImageBufAlgo::color_map(src, 0, "inferno");
  std::vector<float> rgb(size_t(n) * 3);
  EXPECT_TRUE(mapped.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, rgb.data()));
  for (float& v : rgb) v = srgb_encode(v);
  return rgb;
}

TEST(ColourMap, InfernoIsOpenImageIOsBitForBit) {
  // Costs from 0 past the top of the map: every knot exactly, a fine ramp, random values,
  // and what the map clamps (negative, NaN, infinity). cost_image scales by its 99th
  // percentile; with the top 1% of the costs at 1000 that is 1000.
  std::vector<float> cost;
  for (int k = 0; k <= 16; ++k) cost.push_back(1000.0f * float(k) / 16.0f);
  for (int i = 0; i < 20000; ++i) cost.push_back(1000.0f * float(i) / 20000.0f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> any(0.0f, 1000.0f);
  for (int i = 0; i < 20000; ++i) cost.push_back(any(rng));
  for (float v : {-1.0f, std::numeric_limits<float>::quiet_NaN(),
                  std::numeric_limits<float>::infinity(), 1e-30f, 999.9999f})
    cost.push_back(v);
  const size_t top = cost.size() / 50;
  for (size_t i = 0; i < top; ++i) cost.push_back(1000.0f);

  FrameBuffers fb;
  fb.reset(int(cost.size()), 1, glm::vec3(0.0f));
  std::copy(cost.begin(), cost.end(), fb.cost.begin());
  float scale = 0.0f;
  const Image ours = cost_image(fb, &scale);
  ASSERT_EQ(scale, 1000.0f);
  ASSERT_EQ(ours.pixels.size(), cost.size() * 3);

  // What rvr maps: cost / scale, clamped to [0, 1] with NaN as 0.
  std::vector<float> scaled;
  for (float c : cost) {
    const float v = c * (1.0f / scale);
    scaled.push_back(v > 0.0f ? std::min(v, 1.0f) : 0.0f);
  }
  const std::vector<float> theirs = library_inferno(scaled);
  size_t differing = 0, first = 0;
  for (size_t i = 0; i < theirs.size(); ++i)
    if (std::memcmp(&ours.pixels[i], &theirs[i], sizeof(float)) != 0 && differing++ == 0) first = i;
  EXPECT_EQ(differing, 0u) << "first at value " << first / 3 << " (cost " << cost[first / 3]
                           << ", channel " << first % 3 << "): " << ours.pixels[first] << " vs "
                           << theirs[first];
}

}  // namespace
