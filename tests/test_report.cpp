// metrics.json and report.html of `rvr compare`.
//
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "report.h"
#include "rvr/shared/image_io.h"

namespace fs = std::filesystem;
using namespace rvr;

namespace {

size_t count_of(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

ReportInput sample_input(const std::string& out_dir) {
  ReportInput in;
  in.scene = "builtin:cornell";
  in.width = 8;
  in.height = 6;
  in.mode = "local";
  in.out_dir = out_dir;
  in.command_line = "rvr compare builtin:cornell -o out --renderers raster,raytrace";
  ReportRenderer a{"raster", "raster.png", 0.12, {}, {{"time.render", 0.1}, {"fragments", 99}},
                   "",       0.0,          0.0};
  ReportRenderer b{"raytrace",
                   "raytrace.png",
                   0.4,
                   {"csg objects skipped: <1> & \"more\""},
                   {{"time.build", 0.01}, {"time.render", 0.38}, {"rays.primary", 48}},
                   "raytrace.cost.png",
                   31.0,
                   12.5};
  in.renderers = {a, b};
  in.metrics.visibility = {48, 47.0 / 48.0, 1, 0};
  in.metrics.depth = {0.0004, 0.00001};
  in.metrics.color = {0.004, 47.9, 0.21, 0.998};
  in.heat_map_scale = 0.1f;
  return in;
}

class ReportDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rvr-report-test-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    Image img;
    img.width = 8;
    img.height = 6;
    img.channels = 3;
    img.pixels.assign(8 * 6 * 3, 0.5f);
    for (const char* name :
         {"raster.png", "raytrace.png", "raytrace.cost.png", "diff.png", "id_mismatch.png"})
      ASSERT_TRUE(write_image((dir_ / name).string(), img).ok());
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

}  // namespace

TEST(Base64, KnownVectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(MetricsJson, HasEveryRequiredField) {
  auto doc = nlohmann::json::parse(metrics_json(sample_input("out")));
  EXPECT_EQ(doc["scene"], "builtin:cornell");
  EXPECT_EQ(doc["width"], 8);
  EXPECT_EQ(doc["height"], 6);
  EXPECT_EQ(doc["mode"], "local");
  ASSERT_TRUE(doc["renderers"].is_object());
  for (const char* name : {"raster", "raytrace"}) {
    const auto& r = doc["renderers"][name];
    ASSERT_TRUE(r.is_object()) << name;
    EXPECT_TRUE(r["seconds"].is_number()) << name;
    EXPECT_TRUE(r["warnings"].is_array()) << name;
    EXPECT_TRUE(r["stats"].is_object()) << name;
  }
  EXPECT_DOUBLE_EQ(doc["renderers"]["raster"]["seconds"].get<double>(), 0.12);
  EXPECT_EQ(doc["renderers"]["raytrace"]["warnings"][0], "csg objects skipped: <1> & \"more\"");
  EXPECT_EQ(doc["renderers"]["raytrace"]["stats"]["rays.primary"], 48);
  for (const char* key : {"pixels", "id_agreement", "mismatched_pixels", "mismatched_off_edge"})
    EXPECT_TRUE(doc["visibility"][key].is_number()) << key;
  EXPECT_EQ(doc["visibility"]["pixels"], 48);
  EXPECT_EQ(doc["visibility"]["mismatched_pixels"], 1);
  EXPECT_EQ(doc["visibility"]["mismatched_off_edge"], 0);
  for (const char* key : {"max_rel_error", "mean_rel_error"})
    EXPECT_TRUE(doc["depth"][key].is_number()) << key;
  for (const char* key : {"rmse", "psnr_db", "max_abs", "ssim"})
    EXPECT_TRUE(doc["color"][key].is_number()) << key;
  EXPECT_DOUBLE_EQ(doc["color"]["psnr_db"].get<double>(), 47.9);
  EXPECT_EQ(doc["command"], "rvr compare builtin:cornell -o out --renderers raster,raytrace");
  EXPECT_EQ(doc["heat_map_scale"].get<double>(), 0.1);
  // The work-per-pixel picture, only for a renderer that reports work.
  EXPECT_FALSE(doc["renderers"]["raster"].contains("cost"));
  EXPECT_EQ(doc["renderers"]["raytrace"]["cost"]["image"], "raytrace.cost.png");
  EXPECT_EQ(doc["renderers"]["raytrace"]["cost"]["mean"], 12.5);
  EXPECT_EQ(doc["renderers"]["raytrace"]["cost"]["scale"], 31.0);
}

TEST(MetricsJson, InfiniteAndNanValuesStayValidJson) {
  ReportInput in = sample_input("out");
  in.metrics.color.psnr_db = std::numeric_limits<double>::infinity();
  in.metrics.depth.max_rel_error = std::numeric_limits<double>::quiet_NaN();
  in.renderers[0].stats["weird"] = std::numeric_limits<double>::infinity();
  std::string text = metrics_json(in);
  EXPECT_EQ(text.find("inf"), std::string::npos);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  auto doc = nlohmann::json::parse(text);  // throws when invalid
  EXPECT_EQ(doc["color"]["psnr_db"], 999.0);
  EXPECT_TRUE(doc["depth"]["max_rel_error"].is_null());
  EXPECT_TRUE(doc["renderers"]["raster"]["stats"]["weird"].is_null());
}

TEST(MetricsJson, DuplicateRendererNamesAreKeptApart) {
  ReportInput in = sample_input("out");
  in.renderers[1].name = "raster";
  auto doc = nlohmann::json::parse(metrics_json(in));
  EXPECT_TRUE(doc["renderers"].contains("raster"));
  EXPECT_TRUE(doc["renderers"].contains("raster-2"));
}

TEST_F(ReportDir, HtmlIsSelfContained) {
  auto html = report_html(sample_input(dir_.string()));
  ASSERT_TRUE(html.ok()) << html.error().message;
  const std::string& h = html.value();
  EXPECT_EQ(h.rfind("<!DOCTYPE html>", 0), 0u);
  // Both renders (side by side and in the flip view), diff.png, id_mismatch.png and the
  // cost picture of the renderer that has one.
  EXPECT_EQ(count_of(h, "data:image/png;base64,"), 7u);
  EXPECT_NE(h.find("raytrace.cost.png</b>: BVH nodes visited + primitive tests per pixel; mean "
                   "12.5, yellow-white &ge; 31"),
            std::string::npos);
  EXPECT_NE(h.find("<b>raster</b>: no per-pixel work reported"), std::string::npos);
  EXPECT_EQ(h.find("http"), std::string::npos);
  EXPECT_EQ(h.find("<link"), std::string::npos);
  EXPECT_EQ(h.find("<script src"), std::string::npos);
  EXPECT_NE(h.find("rvr compare builtin:cornell -o out --renderers raster,raytrace"),
            std::string::npos);
  // Warnings are shown, escaped.
  EXPECT_NE(h.find("csg objects skipped: &lt;1&gt; &amp; &quot;more&quot;"), std::string::npos);
  EXPECT_EQ(h.find("<1>"), std::string::npos);
  for (const char* word : {"id_agreement", "mismatched_off_edge", "max_rel_error", "psnr_db",
                           "ssim", "time.render", "time.build", "diff.png", "id_mismatch.png"})
    EXPECT_NE(h.find(word), std::string::npos) << word;
  EXPECT_NE(h.find("</html>"), std::string::npos);
}

TEST_F(ReportDir, EmbeddedImageDecodesToTheFile) {
  auto html = report_html(sample_input(dir_.string()));
  ASSERT_TRUE(html.ok());
  std::ifstream in(dir_ / "diff.png", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html->find("data:image/png;base64," + base64(bytes) + "\""), std::string::npos);
}

TEST_F(ReportDir, MissingImageIsAnError) {
  fs::remove(dir_ / "id_mismatch.png");
  auto html = report_html(sample_input(dir_.string()));
  ASSERT_FALSE(html.ok());
  EXPECT_NE(html.error().message.find("id_mismatch.png"), std::string::npos);
}
