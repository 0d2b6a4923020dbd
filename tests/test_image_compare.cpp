// Image I/O (OpenImageIO, atomic writes, AOVs) and the comparison metrics.
#include <gtest/gtest.h>
#include <stdint.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <initializer_list>
#include <limits>
#include <random>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/check.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/image_codec/image_io.h"

namespace fs = std::filesystem;
using namespace rvr;

namespace {

// A fresh, empty folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() / ("rvr-test-" + std::to_string(::getpid()) + "-" +
                                         info->test_suite_name() + "-" + info->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::vector<std::string> list_dir(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

Image make_image(int w, int h, int c, uint32_t seed, float lo = 0.0f, float hi = 1.0f) {
  Image img;
  img.width = w;
  img.height = h;
  img.channels = c;
  img.pixels.resize(size_t(w) * h * c);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(lo, hi);
  for (float& v : img.pixels) v = dist(rng);
  return img;
}

float srgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

// A flat frame: object 0, primitive 0 everywhere, depth 5, colour grey.
FrameBuffers flat(int w, int h, glm::vec3 colour = glm::vec3(0.5f)) {
  FrameBuffers fb;
  fb.reset(w, h, glm::vec3(0.0f));
  for (size_t i = 0; i < fb.pixel_count(); ++i) {
    fb.object_id[i] = 0;
    fb.primitive_id[i] = 0;
    fb.depth[i] = 5.0f;
    fb.colour[i] = colour;
    fb.normal[i] = glm::vec3(0, 0, 1);
  }
  return fb;
}

// Left half object 0, right half object 1 (the boundary between columns w/2-1 and w/2).
FrameBuffers two_halves(int w, int h) {
  FrameBuffers fb = flat(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = w / 2; x < w; ++x) fb.object_id[fb.index(x, y)] = 1;
  return fb;
}

}  // namespace

// ---------------------------------------------------------------------------------- image I/O

TEST(ImageIo, ExrRoundTripIsExactWithChannelNames) {
  TempDir dir;
  Image img = make_image(7, 5, 2, 1, -3.0f, 1e4f);
  img.channel_names = {"id", "prim"};
  img.at(0, 0, 0) = std::numeric_limits<float>::infinity();
  auto st = write_image(dir / "a.exr", img);
  ASSERT_TRUE(st.ok()) << st.error().message;
  auto back = read_image(dir / "a.exr");
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->width, 7);
  EXPECT_EQ(back->height, 5);
  ASSERT_EQ(back->channels, 2);
  EXPECT_EQ(back->channel_names, (std::vector<std::string>{"id", "prim"}));
  EXPECT_EQ(back->pixels, img.pixels);  // bit exact, +inf included
}

TEST(ImageIo, PngRoundTripWithinOneStepAfterSrgb) {
  TempDir dir;
  Image img = make_image(16, 9, 3, 2, -0.2f, 1.3f);  // out-of-range values get clamped
  img.at(3, 4, 1) = 0.002f;                          // the linear toe of the transfer
  ASSERT_TRUE(write_image(dir / "a.png", img).ok());
  auto back = read_image(dir / "a.png");
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->channels, 3);
  ASSERT_EQ(back->pixels.size(), img.pixels.size());
  for (size_t i = 0; i < img.pixels.size(); ++i)
    ASSERT_NEAR(back->pixels[i], srgb(img.pixels[i]), 1.0f / 255.0f) << "value " << i;
}

TEST(ImageIo, PngWithoutTransferKeepsDisplayValues) {
  TempDir dir;
  Image img = make_image(4, 4, 3, 3);
  ASSERT_TRUE(write_image(dir / "a.png", img, /*linear_to_srgb=*/false).ok());
  auto back = read_image(dir / "a.png");
  ASSERT_TRUE(back.ok());
  for (size_t i = 0; i < img.pixels.size(); ++i)
    ASSERT_NEAR(back->pixels[i], img.pixels[i], 0.5f / 255.0f + 1e-6f);
}

TEST(ImageIo, OtherFormatsRoundTrip) {
  TempDir dir;
  Image img = make_image(5, 3, 3, 4);
  for (const char* name : {"a.tif", "a.ppm"}) {
    ASSERT_TRUE(write_image(dir / name, img, false).ok()) << name;
    auto back = read_image(dir / name);
    ASSERT_TRUE(back.ok()) << name << ": " << back.error().message;
    ASSERT_EQ(back->pixels.size(), img.pixels.size());
    for (size_t i = 0; i < img.pixels.size(); ++i)
      ASSERT_NEAR(back->pixels[i], img.pixels[i], 0.5f / 255.0f + 1e-6f) << name;
  }
}

TEST(ImageIo, NoTemporaryFileIsLeftAfterWriting) {
  TempDir dir;
  ASSERT_TRUE(write_image(dir / "out.png", make_image(3, 3, 3, 5)).ok());
  ASSERT_TRUE(write_image(dir / "out.exr", make_image(3, 3, 1, 5)).ok());
  ASSERT_TRUE(write_text_file(dir / "m.json", "{}\n").ok());
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"m.json", "out.exr", "out.png"}));
}

TEST(ImageIo, OverwritesAnExistingFile) {
  TempDir dir;
  ASSERT_TRUE(write_text_file(dir / "out.txt", "first, longer text").ok());
  ASSERT_TRUE(write_text_file(dir / "out.txt", "second").ok());
  std::ifstream in(dir / "out.txt");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "second");
}

TEST(ImageIo, CreatesMissingFolders) {
  TempDir dir;
  std::string path = dir / "a/b/c/out.png";
  ASSERT_TRUE(write_image(path, make_image(2, 2, 3, 6)).ok());
  EXPECT_TRUE(fs::is_regular_file(path));
  ASSERT_TRUE(write_text_file(dir / "x/y/z.txt", "hello").ok());
  EXPECT_TRUE(fs::is_regular_file(dir / "x/y/z.txt"));
}

TEST(ImageIo, PathUnderARegularFileFailsCleanly) {
  TempDir dir;
  ASSERT_TRUE(write_text_file(dir / "file", "not a folder").ok());
  std::string path = dir / "file/sub/out.png";
  auto st = write_image(path, make_image(2, 2, 3, 7));
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().kind, ErrorKind::BadInput);
  EXPECT_EQ(st.error().message.rfind("cannot write '" + path + "': ", 0), 0u) << st.error().message;
  auto st2 = write_text_file(dir / "file/x.json", "{}");
  ASSERT_FALSE(st2.ok());
  EXPECT_NE(st2.error().message.find(dir / "file/x.json"), std::string::npos);
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"file"}));
}

TEST(ImageIo, FailedRenameRemovesTheTemporary) {
  TempDir dir;
  fs::create_directories(dir / "taken.png/inside");  // a folder where the file should go
  auto st = write_image(dir / "taken.png", make_image(2, 2, 3, 8));
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("cannot write '" + (dir / "taken.png") + "'"),
            std::string::npos);
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"taken.png"}));
  EXPECT_FALSE(write_text_file(dir / "taken.png", "x").ok());
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"taken.png"}));
}

TEST(ImageIo, UnknownExtensionIsAnError) {
  TempDir dir;
  auto st = write_image(dir / "out.nosuchformat", make_image(2, 2, 3, 9));
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("out.nosuchformat"), std::string::npos);
  EXPECT_TRUE(list_dir(dir.path()).empty());
}

TEST(ImageIo, InvalidImageIsAnError) {
  TempDir dir;
  Image img = make_image(2, 2, 3, 10);
  img.pixels.pop_back();
  EXPECT_FALSE(write_image(dir / "out.png", img).ok());
  EXPECT_TRUE(list_dir(dir.path()).empty());
}

TEST(ImageIo, ReadingMissingOrBadFilesFails) {
  TempDir dir;
  auto missing = read_image(dir / "none.png");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().kind, ErrorKind::BadInput);
  EXPECT_EQ(missing.error().message.rfind("cannot read '" + (dir / "none.png") + "': ", 0), 0u)
      << missing.error().message;
  ASSERT_TRUE(write_text_file(dir / "junk.png", "this is no png").ok());
  auto junk = read_image(dir / "junk.png");
  ASSERT_FALSE(junk.ok());
  EXPECT_NE(junk.error().message.find("junk.png"), std::string::npos);
}

TEST(ImageIo, ColorImageCopiesTheLinearColour) {
  FrameBuffers fb = flat(3, 2, glm::vec3(0.1f, 0.2f, 0.3f));
  fb.colour[fb.index(2, 1)] = glm::vec3(2.0f, -1.0f, 0.0f);
  Image img = colour_image(fb);
  ASSERT_EQ(img.channels, 3);
  EXPECT_FLOAT_EQ(img.at(0, 0, 1), 0.2f);
  EXPECT_FLOAT_EQ(img.at(2, 1, 0), 2.0f);
  EXPECT_FLOAT_EQ(img.at(2, 1, 1), -1.0f);
}

TEST(Aovs, WritesEveryRequestedFile) {
  TempDir dir;
  FrameBuffers fb;
  fb.reset(4, 3, glm::vec3(0.0f));
  fb.object_id[fb.index(1, 1)] = 2;
  fb.primitive_id[fb.index(1, 1)] = 7;
  fb.depth[fb.index(1, 1)] = 3.5f;
  fb.normal[fb.index(1, 1)] = glm::vec3(0.0f, 1.0f, 0.0f);
  for (size_t i = 0; i < fb.pixel_count(); ++i) fb.cost[i] = float(i);
  auto st = write_aovs(dir / "sub/render.png", fb, {"depth", "id", "normal", "cost"});
  ASSERT_TRUE(st.ok()) << st.error().message;
  EXPECT_EQ(list_dir(dir.path() / "sub"),
            (std::vector<std::string>{"render.cost.exr", "render.cost.png", "render.depth.exr",
                                      "render.id.exr", "render.normal.exr"}));

  auto depth = read_image(dir / "sub/render.depth.exr");
  ASSERT_TRUE(depth.ok());
  ASSERT_EQ(depth->channels, 1);
  EXPECT_FLOAT_EQ(depth->at(1, 1, 0), 3.5f);
  EXPECT_TRUE(std::isinf(depth->at(0, 0, 0)) && depth->at(0, 0, 0) > 0);

  auto id = read_image(dir / "sub/render.id.exr");
  ASSERT_TRUE(id.ok());
  ASSERT_EQ(id->channels, 2);
  EXPECT_EQ(id->channel_names, (std::vector<std::string>{"id", "prim"}));
  EXPECT_EQ(id->at(1, 1, 0), 2.0f);
  EXPECT_EQ(id->at(1, 1, 1), 7.0f);
  EXPECT_EQ(id->at(3, 2, 0), -1.0f);
  EXPECT_EQ(id->at(3, 2, 1), -1.0f);

  auto normal = read_image(dir / "sub/render.normal.exr");
  ASSERT_TRUE(normal.ok());
  ASSERT_EQ(normal->channels, 3);
  EXPECT_EQ(normal->at(1, 1, 1), 1.0f);

  auto cost = read_image(dir / "sub/render.cost.exr");
  ASSERT_TRUE(cost.ok());
  ASSERT_EQ(cost->channels, 1);
  EXPECT_EQ(cost->at(3, 2, 0), 11.0f);

  auto cost_png = read_image(dir / "sub/render.cost.png");
  ASSERT_TRUE(cost_png.ok());
  ASSERT_EQ(cost_png->channels, 3);
  // Inferno: dark for no work, bright (yellow) for the most.
  EXPECT_LT(cost_png->at(0, 0, 0) + cost_png->at(0, 0, 1), 0.1f);
  EXPECT_GT(cost_png->at(3, 2, 0), 0.9f);
  EXPECT_GT(cost_png->at(3, 2, 1), 0.9f);
}

TEST(Aovs, LodIsTheLevelOfDetailAndNanWhereNothingIsTextured) {
  TempDir dir;
  FrameBuffers fb = flat(3, 2);
  fb.lod.assign(fb.pixel_count(), std::numeric_limits<float>::quiet_NaN());
  fb.lod[fb.index(1, 0)] = 2.75f;
  fb.lod[fb.index(2, 1)] = -1.5f;
  ASSERT_TRUE(write_aovs(dir / "r.png", fb, {"lod"}).ok());
  auto lod = read_image(dir / "r.lod.exr");
  ASSERT_TRUE(lod.ok());
  ASSERT_EQ(lod->channels, 1);
  EXPECT_EQ(lod->channel_names, (std::vector<std::string>{"lod"}));
  EXPECT_EQ(lod->at(1, 0, 0), 2.75f);
  EXPECT_EQ(lod->at(2, 1, 0), -1.5f);
  EXPECT_TRUE(std::isnan(lod->at(0, 0, 0)));
  // An untextured frame has no lod buffer: NaN everywhere.
  fb.lod.clear();
  ASSERT_TRUE(write_aovs(dir / "u.png", fb, {"lod"}).ok());
  auto none = read_image(dir / "u.lod.exr");
  ASSERT_TRUE(none.ok());
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) EXPECT_TRUE(std::isnan(none->at(x, y, 0)));
}

TEST(Aovs, OnlyTheRequestedOnes) {
  TempDir dir;
  FrameBuffers fb = flat(2, 2);
  ASSERT_TRUE(write_aovs(dir / "r.exr", fb, {"depth"}).ok());
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"r.depth.exr"}));
  ASSERT_TRUE(write_aovs(dir / "q.png", fb, {}).ok());
  EXPECT_EQ(list_dir(dir.path()).size(), 1u);
}

TEST(Aovs, UnknownAovIsAnError) {
  TempDir dir;
  auto st = write_aovs(dir / "r.png", flat(2, 2), {"depth", "albedo"});
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().kind, ErrorKind::BadInput);
  EXPECT_EQ(st.error().message, "unknown aov 'albedo' (known: depth, id, normal, cost, lod)");
  EXPECT_TRUE(list_dir(dir.path()).empty());  // nothing written before the check
}

// -------------------------------------------------------------------------------- comparison

TEST(Compare, IdBoundariesMarkBothSidesOfAnEdge) {
  FrameBuffers fb = two_halves(6, 3);
  fb.primitive_id[fb.index(0, 0)] = 4;  // a lone primitive in the corner
  auto edge = id_boundaries(fb);
  ASSERT_EQ(edge.size(), fb.pixel_count());
  for (int y = 0; y < 3; ++y) {
    EXPECT_TRUE(edge[fb.index(2, y)]);
    EXPECT_TRUE(edge[fb.index(3, y)]);
    EXPECT_FALSE(edge[fb.index(5, y)]);
  }
  EXPECT_TRUE(edge[fb.index(0, 0)]);
  EXPECT_TRUE(edge[fb.index(1, 0)]);
  EXPECT_TRUE(edge[fb.index(0, 1)]);
  EXPECT_FALSE(edge[fb.index(1, 1)]);
  EXPECT_FALSE(edge[fb.index(0, 2)]);
}

TEST(Compare, IdenticalBuffersAgreeCompletely) {
  FrameBuffers a = two_halves(32, 24);
  for (size_t i = 0; i < a.pixel_count(); ++i) a.colour[i] = glm::vec3(float(i % 7) / 7.0f);
  auto m = compare_buffers(a, a);
  EXPECT_EQ(m.visibility.pixels, 32u * 24u);
  EXPECT_EQ(m.visibility.id_agreement, 1.0);
  EXPECT_EQ(m.visibility.mismatched_pixels, 0u);
  EXPECT_EQ(m.visibility.classes.not_edge(), 0u);
  EXPECT_EQ(m.depth.max_rel_error, 0.0);
  EXPECT_EQ(m.depth.mean_rel_error, 0.0);
  EXPECT_EQ(m.colour.rmse, 0.0);
  EXPECT_EQ(m.colour.max_abs, 0.0);
  EXPECT_TRUE(std::isinf(m.colour.psnr_db) && m.colour.psnr_db > 0);
  EXPECT_NEAR(m.colour.ssim, 1.0, 1e-12);
}

TEST(Compare, LodDifferenceOverThePixelsTexturedInBoth) {
  FrameBuffers a = flat(10, 10), b = flat(10, 10);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  a.lod.assign(100, nan);
  b.lod.assign(100, nan);
  // Pixels 0-49 textured in both: 49 differ by 0.25, one by 2; 50-59 textured in a only.
  for (size_t i = 0; i < 50; ++i) {
    a.lod[i] = 1.0f + float(i % 5);
    b.lod[i] = a.lod[i] + (i == 7 ? -2.0f : 0.25f);
  }
  for (size_t i = 50; i < 60; ++i) a.lod[i] = 3.0f;
  const ComparisonMetrics m = compare_buffers(a, b);
  EXPECT_EQ(m.lod.pixels, 50u);
  EXPECT_NEAR(m.lod.mean_abs, (49 * 0.25 + 2.0) / 50.0, 1e-12);
  // Nearest rank: the 99th percentile of 50 values is the largest.
  EXPECT_DOUBLE_EQ(m.lod.p99_abs, 2.0);
  // Without a lod buffer on one side (an untextured render) there is nothing to compare.
  b.lod.clear();
  EXPECT_EQ(compare_buffers(a, b).lod.pixels, 0u);
  EXPECT_EQ(compare_buffers(a, b).lod.mean_abs, 0.0);
}

TEST(Compare, LoneMismatchIsExcusedButAWrongRegionCountsItsInterior) {
  FrameBuffers a = flat(9, 9), b = flat(9, 9);
  b.primitive_id[b.index(4, 4)] = 3;  // same object, another primitive: still a mismatch
  auto m = compare_buffers(a, b);
  EXPECT_EQ(m.visibility.mismatched_pixels, 1u);
  // Without a scene the edge class is the id-boundary rule (MismatchContext): its neighbours lie
  // on the boundary it draws in b, so it is an edge.
  EXPECT_EQ(m.visibility.classes.not_edge(), 0u);
  EXPECT_DOUBLE_EQ(m.visibility.id_agreement, 80.0 / 81.0);
  // A 5x5 wrong region: only its centre has no boundary pixel among its 8 neighbours.
  FrameBuffers c = flat(9, 9);
  for (int y = 2; y <= 6; ++y)
    for (int x = 2; x <= 6; ++x) c.object_id[c.index(x, y)] = 5;
  auto m2 = compare_buffers(a, c);
  EXPECT_EQ(m2.visibility.mismatched_pixels, 25u);
  EXPECT_EQ(m2.visibility.classes.not_edge(), 1u);
  // Either way round.
  EXPECT_EQ(compare_buffers(c, a).visibility.classes.not_edge(), 1u);
}

TEST(Compare, MismatchNextToABoundaryIsOnEdge) {
  FrameBuffers a = two_halves(10, 6);
  // An edge tie: the pixel left of the boundary falls to the right-hand object in b.
  FrameBuffers b = a;
  b.object_id[b.index(4, 2)] = 1;
  auto m = compare_buffers(a, b);
  EXPECT_EQ(m.visibility.mismatched_pixels, 1u);
  EXPECT_EQ(m.visibility.classes.not_edge(), 0u);
  // Diagonally next to the boundary (its 3x3 touches it) also counts as on the edge.
  FrameBuffers c = a;
  c.object_id[c.index(3, 2)] = 7;
  auto m2 = compare_buffers(a, c);
  EXPECT_EQ(m2.visibility.mismatched_pixels, 1u);
  EXPECT_EQ(m2.visibility.classes.not_edge(), 0u);
  // A wrong region well inside the left half counts its interior.
  FrameBuffers d = two_halves(14, 9);
  FrameBuffers e = d;
  for (int y = 1; y <= 7; ++y)
    for (int x = 0; x <= 4; ++x) e.object_id[e.index(x, y)] = 7;
  // Rows 3..5 of columns 0..2 have no boundary (x = 4/5, y = 0/1 and 7/8) among neighbours.
  EXPECT_EQ(compare_buffers(d, e).visibility.classes.not_edge(), 9u);
}

TEST(Compare, SilhouetteShiftedByOnePixelIsAllOnEdge) {
  FrameBuffers a;
  a.reset(12, 8, glm::vec3(0.0f));
  FrameBuffers b = a;
  for (int y = 2; y < 6; ++y)
    for (int x = 3; x < 8; ++x) {
      a.object_id[a.index(x, y)] = 0;
      a.primitive_id[a.index(x, y)] = 0;
      a.depth[a.index(x, y)] = 1.0f;
    }
  for (int y = 2; y < 6; ++y)
    for (int x = 3; x < 9; ++x) {  // one column wider
      b.object_id[b.index(x, y)] = 0;
      b.primitive_id[b.index(x, y)] = 0;
      b.depth[b.index(x, y)] = 1.0f;
    }
  auto m = compare_buffers(a, b);
  EXPECT_EQ(m.visibility.mismatched_pixels, 4u);
  EXPECT_EQ(m.visibility.classes.not_edge(), 0u);
  EXPECT_EQ(compare_buffers(b, a).visibility.classes.not_edge(), 0u);
}

TEST(Compare, BackgroundPrimitiveIdIsIgnored) {
  FrameBuffers a;
  a.reset(4, 4, glm::vec3(0.0f));
  FrameBuffers b = a;
  for (auto& p : b.primitive_id) p = 0;  // a renderer that leaves 0 on the background
  EXPECT_EQ(compare_buffers(a, b).visibility.mismatched_pixels, 0u);
}

TEST(Compare, DepthRelativeErrorOnACraftedExample) {
  FrameBuffers a;
  a.reset(4, 1, glm::vec3(0.0f));
  FrameBuffers b = a;
  // x=0: hit in both, 2 vs 2.5 -> 0.5 / 2.5 = 0.2
  // x=1: hit in both, 4 vs 4   -> 0
  // x=2: ids differ            -> excluded
  // x=3: background in both    -> excluded
  a.object_id[0] = b.object_id[0] = 1;
  a.primitive_id[0] = b.primitive_id[0] = 0;
  a.depth[0] = 2.0f;
  b.depth[0] = 2.5f;
  a.object_id[1] = b.object_id[1] = 1;
  a.primitive_id[1] = b.primitive_id[1] = 1;
  a.depth[1] = b.depth[1] = 4.0f;
  a.object_id[2] = 1;
  b.object_id[2] = 2;
  a.primitive_id[2] = b.primitive_id[2] = 0;
  a.depth[2] = 1.0f;
  b.depth[2] = 100.0f;
  auto m = compare_buffers(a, b);
  EXPECT_DOUBLE_EQ(m.depth.max_rel_error, 0.2);
  EXPECT_DOUBLE_EQ(m.depth.mean_rel_error, 0.1);
  EXPECT_EQ(m.visibility.mismatched_pixels, 1u);
}

TEST(Compare, ConstantOffsetGivesKnownRmseAndPsnr) {
  FrameBuffers a = flat(40, 30, glm::vec3(0.25f)), b = flat(40, 30, glm::vec3(0.26f));
  auto m = compare_buffers(a, b);
  EXPECT_NEAR(m.colour.rmse, 0.01, 1e-6);
  EXPECT_NEAR(m.colour.psnr_db, 40.0, 1e-3);
  EXPECT_NEAR(m.colour.max_abs, 0.01, 1e-6);
  EXPECT_LT(m.colour.ssim, 1.0);
  EXPECT_GT(m.colour.ssim, 0.99);  // a tiny shift of the mean barely changes the structure
}

// SSIM (Wang et al. 2004) of two constant images is the luminance term alone, the same in every
// window: (2 a b + C1) / (a^2 + b^2 + C1) with C1 = 0.01^2 (the variances and covariance are 0,
// so the contrast-structure term is C2 / C2). Grey colours have luminance equal to the grey.
TEST(Compare, SsimOfConstantImagesIsTheLuminanceTerm) {
  const double C1 = 0.01 * 0.01;
  for (auto [a, b] : {std::pair{0.25, 0.26}, std::pair{0.5, 0.4}, std::pair{0.1, 0.9}}) {
    double expected = (2 * a * b + C1) / (a * a + b * b + C1);
    double ssim =
        compare_buffers(flat(40, 30, glm::vec3(float(a))), flat(40, 30, glm::vec3(float(b))))
            .colour.ssim;
    EXPECT_NEAR(ssim, expected, 1e-6) << a << " vs " << b;
  }
  // Identical images with structure: every window's two terms are exactly 1.
  FrameBuffers a = flat(64, 48);
  for (size_t i = 0; i < a.pixel_count(); ++i)
    a.colour[i] = glm::vec3(float((i * 37) % 101) / 100.0f);
  EXPECT_NEAR(compare_buffers(a, a).colour.ssim, 1.0, 1e-12);
}

// Depth percentiles and outliers on a crafted frame: 100x100 pixels, column 0 another object,
// depth 4 in A and 4 / (1 - e) in B, so each pixel's relative error is e. Errors: 9880 pixels
// 0, 100 at 1e-4, 15 at 5e-4, 5 above the outlier threshold 1e-3 (2 next to column 0, that
// is on an object's outline; 3 in the middle). Nearest rank over 10000 pixels: p99 is the
// 9900th smallest (1e-4), p99.9 the 9990th (5e-4).
TEST(Compare, DepthPercentilesAndOutliersByCause) {
  FrameBuffers a = flat(100, 100), b;
  for (int y = 0; y < 100; ++y) a.object_id[a.index(0, y)] = 1;
  for (float& d : a.depth) d = 4.0f;
  b = a;
  auto set_error = [&](int x, int y, double e) { b.depth[b.index(x, y)] = float(4.0 / (1.0 - e)); };
  int placed = 0;
  for (int y = 10; y < 90 && placed < 100; ++y)
    for (int x = 20; x < 30 && placed < 100; ++x, ++placed) set_error(x, y, 1e-4);
  for (int k = 0; k < 15; ++k) set_error(40 + k, 50, 5e-4);
  set_error(1, 20, 6e-3);  // next to column 0: outline
  set_error(1, 70, 2e-3);  // outline
  set_error(60, 60, 5e-3);
  set_error(70, 70, 4e-3);
  set_error(80, 80, 3e-3);
  const DepthMetrics m = compare_buffers(a, b).depth;
  EXPECT_NEAR(m.max_rel_error, 6e-3, 1e-7);
  EXPECT_NEAR(m.mean_rel_error, (100 * 1e-4 + 15 * 5e-4 + 20e-3) / 10000, 1e-9);
  EXPECT_NEAR(m.p99_rel_error, 1e-4, 1e-7);
  EXPECT_NEAR(m.p999_rel_error, 5e-4, 1e-7);
  EXPECT_EQ(m.outliers, 5u);
  EXPECT_EQ(m.outliers_at_silhouettes, 2u);
  EXPECT_EQ(m.outliers_elsewhere, 3u);
  ASSERT_EQ(m.worst_outliers.size(), 5u);
  const int expected_x[] = {1, 60, 70, 80, 1}, expected_y[] = {20, 60, 70, 80, 70};
  for (size_t k = 0; k < 5; ++k) {
    const DepthOutlier& o = m.worst_outliers[k];
    EXPECT_EQ(o.x, expected_x[k]) << k;
    EXPECT_EQ(o.y, expected_y[k]) << k;
    EXPECT_EQ(o.object, 0u);
    EXPECT_EQ(o.depth_a, 4.0f);
    EXPECT_EQ(o.cause, o.x == 1 ? DepthOutlierCause::Silhouette : DepthOutlierCause::Elsewhere)
        << k;
  }
  // Nothing compared (all background): every statistic is 0.
  FrameBuffers empty;
  empty.reset(8, 8, glm::vec3(0.0f));
  const DepthMetrics none = compare_buffers(empty, empty).depth;
  EXPECT_EQ(none.p99_rel_error, 0.0);
  EXPECT_EQ(none.outliers, 0u);
}

TEST(Compare, SsimDropsForNoise) {
  FrameBuffers a = flat(64, 48), b = a;
  std::mt19937 rng(42);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  for (auto& c : b.colour) c += glm::vec3(noise(rng));
  auto m = compare_buffers(a, b);
  EXPECT_LT(m.colour.ssim, 0.5);
  EXPECT_GT(m.colour.ssim, -1.0);
  FrameBuffers c = a;
  for (size_t i = 0; i < c.pixel_count(); i += 5) c.colour[i] += glm::vec3(0.02f);
  double mild = compare_buffers(a, c).colour.ssim;
  EXPECT_LT(mild, 1.0);
  EXPECT_GT(mild, m.colour.ssim);
}

TEST(Compare, SsimOnImagesSmallerThanTheWindow) {
  for (auto [w, h] : {std::pair{1, 1}, std::pair{3, 2}, std::pair{2, 20}}) {
    FrameBuffers a = flat(w, h), b = flat(w, h, glm::vec3(0.4f));
    b.colour[0] = glm::vec3(0.9f);
    double s = compare_buffers(a, b).colour.ssim;
    EXPECT_TRUE(std::isfinite(s)) << w << "x" << h;
    EXPECT_LT(s, 1.0);
    EXPECT_NEAR(compare_buffers(a, a).colour.ssim, 1.0, 1e-12);
  }
}

TEST(Compare, FastOnALargeFrame) {
  FrameBuffers a = two_halves(2048, 1536), b = a;
  for (size_t i = 0; i < b.pixel_count(); i += 3) b.colour[i] += glm::vec3(0.01f);
  auto t0 = std::chrono::steady_clock::now();
  auto m = compare_buffers(a, b);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(m.visibility.pixels, 2048u * 1536u);
  // About 0.3 s here; generous for a shared, noisy machine and debug builds.
  EXPECT_LT(seconds, 15.0);
  RecordProperty("seconds", std::to_string(seconds));
}

TEST(Compare, DifferentSizesReportTotalDisagreement) {
  auto m = compare_buffers(flat(4, 4), flat(3, 4));
  EXPECT_EQ(m.visibility.id_agreement, 0.0);
  EXPECT_EQ(m.visibility.mismatched_pixels, 16u);
}

// ------------------------------------------------------------------------------ image diffs

TEST(DiffImages, SizeMismatchIsAnError) {
  auto d = diff_images(make_image(640, 480, 3, 1), make_image(320, 240, 3, 1));
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().kind, ErrorKind::BadInput);
  EXPECT_EQ(d.error().message, "images differ in size: 640x480 vs 320x240");
}

TEST(DiffImages, ChannelMismatchIsAnError) {
  auto d = diff_images(make_image(4, 4, 3, 1), make_image(4, 4, 4, 1));
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().kind, ErrorKind::BadInput);
  EXPECT_NE(d.error().message.find("channel"), std::string::npos);
}

TEST(DiffImages, StatisticsAndWhereTheMaximumIs) {
  Image a = make_image(5, 4, 3, 11), b = a;
  for (float& v : b.pixels) v += 0.01f;
  b.at(3, 2, 1) = a.at(3, 2, 1) + 0.5f;
  auto d = diff_images(a, b);
  ASSERT_TRUE(d.ok());
  const double n = 5 * 4 * 3;
  EXPECT_NEAR(d->mean_abs, ((n - 1) * 0.01 + 0.5) / n, 1e-6);
  EXPECT_NEAR(d->rmse, std::sqrt(((n - 1) * 1e-4 + 0.25) / n), 1e-6);
  EXPECT_NEAR(d->psnr_db, 20 * std::log10(1 / d->rmse), 1e-9);
  EXPECT_NEAR(d->max_abs, 0.5, 1e-6);
  EXPECT_EQ(d->max_x, 3);
  EXPECT_EQ(d->max_y, 2);
  EXPECT_EQ(d->max_channel, 1);

  auto same = diff_images(a, a);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->rmse, 0.0);
  EXPECT_TRUE(std::isinf(same->psnr_db));
}

TEST(HeatMap, InfernoFromBlackToYellow) {
  Image a = make_image(4, 1, 3, 12), b = a;
  b.at(1, 0, 2) += 0.05f;  // half of the scale
  b.at(2, 0, 0) += 0.1f;   // the top of the scale
  b.at(3, 0, 1) -= 5.0f;   // beyond it: clamped to the top
  Image h = diff_heat_map(a, b, 0.1f);
  ASSERT_EQ(h.width, 4);
  ASSERT_EQ(h.height, 1);
  ASSERT_EQ(h.channels, 3);
  for (float v : h.pixels) {
    EXPECT_GE(v, 0.0f);
    EXPECT_LE(v, 1.0f);
  }
  // Inferno, display referred: 0 -> near black, 0.5 -> (0.74, 0.22, 0.33), 1 -> (0.99, 1, 0.64).
  EXPECT_LT(h.at(0, 0, 0) + h.at(0, 0, 1) + h.at(0, 0, 2), 0.05f);
  EXPECT_NEAR(h.at(1, 0, 0), 0.735f, 0.03f);
  EXPECT_NEAR(h.at(1, 0, 1), 0.216f, 0.03f);
  EXPECT_NEAR(h.at(1, 0, 2), 0.330f, 0.03f);
  EXPECT_NEAR(h.at(2, 0, 0), 0.988f, 0.02f);
  EXPECT_NEAR(h.at(2, 0, 1), 0.998f, 0.02f);
  EXPECT_NEAR(h.at(2, 0, 2), 0.645f, 0.03f);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(h.at(3, 0, c), h.at(2, 0, c));
}

TEST(IdMismatchImage, RedWhereObjectsDifferGreyElsewhere) {
  FrameBuffers a = two_halves(4, 2), b = a;
  a.colour[a.index(0, 0)] = glm::vec3(1.0f);
  a.colour[a.index(1, 0)] = glm::vec3(0.0f);
  b.object_id[b.index(2, 1)] = 0;     // object differs
  b.primitive_id[b.index(3, 1)] = 9;  // only the primitive differs: not red
  Image img = id_mismatch_image(a, b);
  ASSERT_EQ(img.channels, 3);
  EXPECT_EQ(img.at(2, 1, 0), 1.0f);
  EXPECT_EQ(img.at(2, 1, 1), 0.0f);
  EXPECT_EQ(img.at(2, 1, 2), 0.0f);
  EXPECT_FLOAT_EQ(img.at(0, 0, 0), 1.0f);
  EXPECT_FLOAT_EQ(img.at(1, 0, 1), 0.0f);
  // a's linear grey 0.5 is shown sRGB-encoded (about 0.735) with equal channels.
  EXPECT_NEAR(img.at(3, 1, 0), srgb(0.5f), 1e-5f);
  EXPECT_EQ(img.at(3, 1, 0), img.at(3, 1, 1));
  EXPECT_EQ(img.at(3, 1, 1), img.at(3, 1, 2));
}

TEST(DepthDiffImage, LogScaleAndBackgroundColours) {
  FrameBuffers a = flat(8, 1), b = flat(8, 1);
  for (int x = 0; x < 8; ++x) a.depth[x] = b.depth[x] = 1.0f;
  // x=0: same depth -> black. x=1: rel 10^-3.5, half way up 1e-6..1e-1 in log10 -> inferno(0.5).
  b.depth[1] = 1.0f - std::pow(10.0f, -3.5f);
  b.depth[2] = 0.9f;                        // rel 0.1: the top of the map
  a.depth[3] = 2.0f;                        // rel 0.5: clamped to the top
  a.object_id[4] = b.object_id[4] = kNoId;  // background in both
  b.object_id[5] = kNoId;                   // hit vs background, both ways
  a.object_id[6] = kNoId;
  b.object_id[7] = 3;  // different object: still a depth difference (here 0)
  Image img = depth_diff_image(a, b);
  ASSERT_EQ(img.width, 8);
  ASSERT_EQ(img.height, 1);
  ASSERT_EQ(img.channels, 3);
  auto pixel = [&](int x) { return glm::vec3(img.at(x, 0, 0), img.at(x, 0, 1), img.at(x, 0, 2)); };
  EXPECT_LT(pixel(0).r + pixel(0).g + pixel(0).b, 0.05f);
  EXPECT_NEAR(pixel(1).r, 0.735f, 0.03f);
  EXPECT_NEAR(pixel(1).g, 0.216f, 0.03f);
  EXPECT_NEAR(pixel(1).b, 0.330f, 0.03f);
  EXPECT_NEAR(pixel(2).r, 0.988f, 0.02f);
  EXPECT_NEAR(pixel(2).g, 0.998f, 0.02f);
  EXPECT_NEAR(pixel(2).b, 0.645f, 0.03f);
  EXPECT_EQ(pixel(3), pixel(2));
  EXPECT_EQ(pixel(4), glm::vec3(0.5f));
  EXPECT_EQ(pixel(5), glm::vec3(0.0f, 1.0f, 1.0f));
  EXPECT_EQ(pixel(6), glm::vec3(0.0f, 1.0f, 1.0f));
  EXPECT_EQ(pixel(7), pixel(0));
}

TEST(DepthDiffImage, ScaleIsAParameterAndBadInputStillGivesAPicture) {
  FrameBuffers a = flat(2, 1), b = flat(2, 1);
  b.depth[0] = 5.0f * (1.0f - 1e-3f);
  b.depth[1] = std::numeric_limits<float>::quiet_NaN();  // a hit with no depth: worst
  // With the top of the map at 1e-3 the first pixel is at the top too.
  Image img = depth_diff_image(a, b, {1e-5f, 1e-3f});
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(img.at(0, 0, c), img.at(1, 0, c), 0.02f);
    EXPECT_GT(img.at(0, 0, c), 0.6f);
  }
  // A smaller b: its missing pixels are hit vs background; a nonsense scale does not crash.
  FrameBuffers small = flat(1, 1);
  Image partial = depth_diff_image(a, small, {-1.0f, 0.0f});
  ASSERT_EQ(partial.width, 2);
  EXPECT_EQ(partial.at(1, 0, 0), 0.0f);
  EXPECT_EQ(partial.at(1, 0, 1), 1.0f);
  EXPECT_EQ(partial.at(1, 0, 2), 1.0f);
  for (float v : partial.pixels) EXPECT_TRUE(std::isfinite(v));
}
