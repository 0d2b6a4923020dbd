// The light PNG/EXR writer (image_codec/src/image_writer.cpp) against OpenImageIO: the same
// write_image call, once through each (RVR_IMAGE_WRITER=openimageio forces the full library),
// read back through OpenImageIO, must give the same size, channel names and pixels, bit for
// bit. The reference is the library rvr wrote with before the light writer existed, not the
// code under test.
#include <gtest/gtest.h>
#include <stdint.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/core/check.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/image_codec/image_io.h"

namespace fs = std::filesystem;
using namespace rvr;

namespace {

class ImageWriter : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rvr_image_writer_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    ::unsetenv("RVR_IMAGE_WRITER");
    fs::remove_all(dir_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// Values over and beyond every byte and sRGB segment: negatives, the linear toe below
// 0.0031308, the whole curve, above 1, huge, NaN and infinities (clamped in 8-bit files, kept
// in EXR). Odd sizes, so a row or column slip shows.
Image test_image(int w, int h, int channels, std::vector<std::string> names, uint32_t seed) {
  Image img;
  img.width = w;
  img.height = h;
  img.channels = channels;
  img.channel_names = std::move(names);
  img.pixels.resize(size_t(w) * h * channels);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-0.1f, 1.2f);
  const float specials[] = {0.0f,
                            -1.0f,
                            0.002f,
                            0.0031308f,
                            1.0f,
                            3.0e38f,
                            std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity()};
  for (size_t i = 0; i < img.pixels.size(); ++i)
    img.pixels[i] = i < std::size(specials) ? specials[i] : unit(rng);
  // Every channel its own ramp along x, so swapped channels or mirrored rows differ.
  for (int y = 0; y < h; ++y)
    for (int c = 0; c < channels; ++c) img.at(w - 1, y, c) = float(y * channels + c) / 256.0f;
  return img;
}

bool library_loaded(const std::string& name) {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line))
    if (line.find(name) != std::string::npos) return true;
  return false;
}

struct Case {
  std::string name;
  Image image;
  bool linear_to_srgb = true;
};

// Writes every case through the light writer, then through OpenImageIO; each pair read back
// (OpenImageIO) must agree in size, channel names and every bit of every value.
void expect_same_as_openimageio(const fs::path& dir, const std::vector<Case>& cases) {
  // ctest runs each case in its own process, where OpenImageIO is not loaded yet and must stay
  // so through the light writes (test_cli checks the same for whole rvr runs).
  const bool full_library_before = library_loaded("libOpenImageIO");
  for (const Case& c : cases)
    ASSERT_TRUE(write_image((dir / ("light_" + c.name)).string(), c.image, c.linear_to_srgb).ok())
        << c.name;
  EXPECT_TRUE(library_loaded("librvr_image_writer.so"));
  if (!full_library_before) {
    EXPECT_FALSE(library_loaded("libOpenImageIO"));
  }
  ::setenv("RVR_IMAGE_WRITER", "openimageio", 1);
  for (const Case& c : cases)
    ASSERT_TRUE(write_image((dir / ("full_" + c.name)).string(), c.image, c.linear_to_srgb).ok())
        << c.name;
  ::unsetenv("RVR_IMAGE_WRITER");
  EXPECT_TRUE(library_loaded("libOpenImageIO"));

  for (const Case& c : cases) {
    Expected<Image> a = read_image((dir / ("light_" + c.name)).string());
    Expected<Image> b = read_image((dir / ("full_" + c.name)).string());
    ASSERT_TRUE(a.ok()) << a.error().message;
    ASSERT_TRUE(b.ok()) << b.error().message;
    EXPECT_EQ(a->width, b->width) << c.name;
    EXPECT_EQ(a->height, b->height) << c.name;
    EXPECT_EQ(a->channels, b->channels) << c.name;
    EXPECT_EQ(a->channel_names, b->channel_names) << c.name;
    ASSERT_EQ(a->pixels.size(), b->pixels.size()) << c.name;
    size_t differing = 0, first = 0;
    for (size_t i = 0; i < a->pixels.size(); ++i)
      if (std::memcmp(&a->pixels[i], &b->pixels[i], sizeof(float)) != 0 && differing++ == 0)
        first = i;
    EXPECT_EQ(differing, 0u) << c.name << ": first at value " << first << " (" << a->pixels[first]
                             << " vs " << b->pixels[first] << ")";
  }
}

TEST_F(ImageWriter, PngIsWhatOpenImageIOWrites) {
  expect_same_as_openimageio(
      dir_, {{"rgb.png", test_image(37, 23, 3, {"R", "G", "B"}, 1), true},
             {"heat.png", test_image(41, 19, 3, {"R", "G", "B"}, 2), false},  // display referred
             {"grey.png", test_image(17, 29, 1, {}, 3), true},
             {"upper.PNG", test_image(5, 7, 3, {}, 4), true}});
}

TEST_F(ImageWriter, ExrIsWhatOpenImageIOWrites) {
  expect_same_as_openimageio(
      dir_, {{"rgb.exr", test_image(37, 23, 3, {"R", "G", "B"}, 5)},
             {"depth.exr", test_image(31, 17, 1, {"Z"}, 6)},
             {"aovs.exr", test_image(13, 11, 5, {"N.x", "N.y", "N.z", "id", "Z"}, 7)}});
}

// The colour-mapped pictures (the cost AOV's OUT.cost.png, compare's heat maps) are drawn
// without OpenImageIO, so that writing a frame's AOVs does not load its ~260 shared libraries
// for one colour map. test_colour_map holds the map to the library's.
TEST_F(ImageWriter, ColourMapsDoNotLoadOpenImageIO) {
  ASSERT_FALSE(library_loaded("libOpenImageIO")) << "loaded before the test: nothing to check";
  FrameBuffers a, b;
  a.reset(24, 16, glm::vec3(0.25f));
  b.reset(24, 16, glm::vec3(0.5f));
  for (size_t i = 0; i < a.pixel_count(); ++i) {
    a.cost[i] = float(i % 17);
    a.object_id[i] = b.object_id[i] = 0;
    a.depth[i] = 2.0f;
    b.depth[i] = 2.0f + 1e-3f * float(i % 5);
  }
  ASSERT_TRUE(write_aovs(path("r.png"), a, {"depth", "id", "normal", "cost"}).ok());
  EXPECT_TRUE(fs::exists(path("r.cost.png")));
  const Image heat = diff_heat_map(colour_image(a), colour_image(b), 0.1f);
  EXPECT_GT(heat.pixels.at(0), 0.5f);  // a difference of 0.25 is at the top of the map
  const Image depth = depth_diff_image(a, b, DepthDiffScale{});
  EXPECT_EQ(depth.width, 24);
  EXPECT_FALSE(library_loaded("libOpenImageIO"));
}

// Images the light writer declines go to OpenImageIO and are still written: alpha (which
// OpenImageIO un-premultiplies in PNG), unnamed EXR channels, other formats.
TEST_F(ImageWriter, WhatTheLightWriterDeclinesOpenImageIOWrites) {
  for (const auto& [name, image] :
       {std::pair{std::string("rgba.png"), test_image(9, 7, 4, {"R", "G", "B", "A"}, 8)},
        std::pair{std::string("unnamed.exr"), test_image(9, 7, 2, {}, 9)},
        std::pair{std::string("rgb.tif"), test_image(9, 7, 3, {"R", "G", "B"}, 10)}}) {
    ASSERT_TRUE(write_image(path(name), image).ok()) << name;
    EXPECT_TRUE(fs::exists(path(name))) << name;
  }
  EXPECT_TRUE(library_loaded("libOpenImageIO"));
}

}  // namespace
