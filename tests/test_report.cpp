// metrics.json and report.html of `rvr compare`.
//
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "base64.h"
#include "render_stats.h"
#include "report.h"
#include "rvr/compare/compare.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/stats.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"

namespace fs = std::filesystem;
using namespace rvr;

namespace {

size_t count_of(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// The first SVG of this class, from its opening tag to the next </svg>.
std::string svg_with_class(const std::string& html, const std::string& cls) {
  size_t at = html.find("<svg class=\"" + cls + "\"");
  if (at == std::string::npos) return "";
  size_t end = html.find("</svg>", at);
  return end == std::string::npos ? "" : html.substr(at, end + 6 - at);
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
                   "",       0.0,          0.0,  {}};
  ReportRenderer b{"raytrace",
                   "raytrace.png",
                   0.4,
                   {"csg objects skipped: <1> & \"more\""},
                   {{"time.build", 0.01}, {"time.render", 0.38}, {"rays.primary", 48}},
                   "raytrace.cost.png",
                   31.0,
                   12.5,
                   {{"kernel", "avx2"}}};
  in.renderers = {a, b};
  in.metrics.visibility.pixels = 48;
  in.metrics.visibility.id_agreement = 47.0 / 48.0;
  in.metrics.visibility.mismatched_pixels = 1;
  in.metrics.visibility.covered_a = 40;
  in.metrics.visibility.covered_b = 39;
  in.metrics.visibility.covered_pixels = 41;
  in.metrics.visibility.covered_fraction = 41.0 / 48.0;
  in.metrics.visibility.covered_agreement = 40.0 / 41.0;
  in.metrics.visibility.classes = {5, 6, 7, 8};
  in.warnings = {"raytrace: nearly all <background>"};
  in.metrics.depth.max_rel_error = 0.0004;
  in.metrics.depth.mean_rel_error = 0.00001;
  in.metrics.depth.p99_rel_error = 0.00007;
  in.metrics.depth.p999_rel_error = 0.0002;
  in.metrics.depth.outliers = 7;
  in.metrics.depth.outliers_at_silhouettes = 2;
  in.metrics.depth.outliers_on_analytic_spheres = 4;
  in.metrics.depth.outliers_elsewhere = 1;
  in.metrics.depth.worst_outliers = {
      {5, 4, 7, 0.0035, 2.5f, 2.51f, DepthOutlierCause::Elsewhere},
      {1, 2, 3, 0.0012, 6.0f, 6.0075f, DepthOutlierCause::Silhouette},
      {3, 3, 6, 0.0011, 4.0f, 4.0044f, DepthOutlierCause::AnalyticSphere}};
  in.metrics.colour = {0.004, 47.9, 0.21, 0.998};
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
    for (const char* name : {"raster.png", "raytrace.png", "raytrace.cost.png", "diff.png",
                             "id_mismatch.png", "depth_diff.png", "mismatch_classes.png"})
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
  // Every metric under its own name: sample_input gives each a different value, so two fields
  // swapped (or one written twice) fail here.
  auto number = [&](const char* group, const char* key) {
    const auto& v = doc[group][key];
    EXPECT_TRUE(v.is_number()) << group << "." << key;
    return v.is_number() ? v.get<double>() : std::nan("");
  };
  EXPECT_EQ(number("visibility", "pixels"), 48.0);
  EXPECT_DOUBLE_EQ(number("visibility", "id_agreement"), 47.0 / 48.0);
  EXPECT_EQ(number("visibility", "mismatched_pixels"), 1.0);
  EXPECT_FALSE(doc["visibility"].contains("mismatched_off_edge"));  // replaced by the classes
  EXPECT_EQ(number("visibility", "covered_a"), 40.0);
  EXPECT_EQ(number("visibility", "covered_b"), 39.0);
  EXPECT_EQ(number("visibility", "covered_pixels"), 41.0);
  EXPECT_DOUBLE_EQ(number("visibility", "covered_fraction"), 41.0 / 48.0);
  EXPECT_DOUBLE_EQ(number("visibility", "covered_agreement"), 40.0 / 41.0);
  const auto& classes = doc["visibility"]["mismatch_classes"];
  EXPECT_EQ(classes["edge"], 5);
  EXPECT_EQ(classes["depth_precision"], 6);
  EXPECT_EQ(classes["occlusion"], 7);
  EXPECT_EQ(classes["coverage"], 8);
  EXPECT_EQ(doc["format"], "rvr-metrics/2");
  EXPECT_EQ(doc["warnings"], nlohmann::json({"raytrace: nearly all <background>"}));
  // One pair, at the top level and as pairs[0].
  ASSERT_EQ(doc["pairs"].size(), 1u);
  EXPECT_EQ(doc["pairs"][0]["compared"], nlohmann::json({"raster", "raytrace"}));
  EXPECT_EQ(doc["pairs"][0]["visibility"], doc["visibility"]);
  EXPECT_EQ(doc["pairs"][0]["files"]["mismatch_classes"], "mismatch_classes.png");
  EXPECT_DOUBLE_EQ(number("depth", "max_rel_error"), 0.0004);
  EXPECT_DOUBLE_EQ(number("depth", "mean_rel_error"), 0.00001);
  EXPECT_DOUBLE_EQ(number("depth", "p99_rel_error"), 0.00007);
  EXPECT_DOUBLE_EQ(number("depth", "p999_rel_error"), 0.0002);
  EXPECT_DOUBLE_EQ(number("depth", "outlier_threshold"), 1e-3);
  EXPECT_EQ(number("depth", "outliers"), 7.0);
  EXPECT_EQ(number("depth", "outliers_at_silhouettes"), 2.0);
  EXPECT_EQ(number("depth", "outliers_on_analytic_spheres"), 4.0);
  EXPECT_EQ(number("depth", "outliers_elsewhere"), 1.0);
  const auto& listed = doc["depth"]["outlier_pixels"];
  ASSERT_EQ(listed.size(), 3u);
  EXPECT_EQ(listed[2]["cause"], "analytic_sphere");
  EXPECT_EQ(listed[0]["x"], 5);
  EXPECT_EQ(listed[0]["y"], 4);
  EXPECT_EQ(listed[0]["object"], 7);
  EXPECT_DOUBLE_EQ(listed[0]["rel_error"].get<double>(), 0.0035);
  EXPECT_DOUBLE_EQ(listed[0]["depth_a"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(listed[0]["depth_b"].get<double>(), 2.51);
  EXPECT_EQ(listed[0]["cause"], "elsewhere");
  EXPECT_EQ(listed[1]["cause"], "silhouette");
  EXPECT_DOUBLE_EQ(listed[1]["depth_b"].get<double>(), 6.0075);
  EXPECT_DOUBLE_EQ(number("color", "rmse"), 0.004);
  EXPECT_DOUBLE_EQ(number("color", "psnr_db"), 47.9);
  EXPECT_DOUBLE_EQ(number("color", "max_abs"), 0.21);
  EXPECT_DOUBLE_EQ(number("color", "ssim"), 0.998);
  EXPECT_DOUBLE_EQ(doc["renderers"]["raytrace"]["seconds"].get<double>(), 0.4);
  EXPECT_EQ(doc["command"], "rvr compare builtin:cornell -o out --renderers raster,raytrace");
  EXPECT_EQ(doc["heat_map_scale"].get<double>(), 0.1);
  // The work-per-pixel picture, only for a renderer that reports work.
  EXPECT_FALSE(doc["renderers"]["raster"].contains("cost"));
  EXPECT_EQ(doc["renderers"]["raytrace"]["cost"]["image"], "raytrace.cost.png");
  EXPECT_EQ(doc["renderers"]["raytrace"]["cost"]["mean"], 12.5);
  EXPECT_EQ(doc["renderers"]["raytrace"]["cost"]["scale"], 31.0);
}

// Counts are whole numbers and written as JSON integers ("peak_memory_bytes": 159305728, not
// 159305728.0); seconds and the declared ratios stay numbers, even when whole (a block fill of
// exactly 1), in --stats and in metrics.json alike.
TEST(StatsJson, CountsAreIntegersSecondsAndRatiosNumbers) {
  const std::map<std::string, double> stats = {
      {"rays.primary", 307200.0},
      {"bvh.nodes_visited", 8178646.0},
      {"memory.raster_bytes", 4.5e9},
      {"zbuffer.fragments.generated", 12.0},
      {"time.render", 0.5},
      {"zbuffer.time.setup", 1.0},
      {"overdraw", 1.0},
      {"zbuffer.overdraw", 2.0},
      {"bvh.block_fill", 1.0},
      {"bvh.node_fill", 0.25},
      {"bvh.sah_cost", 3.0},
      {"rays.shadow", std::numeric_limits<double>::infinity()}};
  const std::set<std::string> counts = {"rays.primary", "bvh.nodes_visited", "memory.raster_bytes",
                                        "zbuffer.fragments.generated"};
  RenderOutput out;
  out.stats = stats;
  Scene scene;
  scene.image.width = 4;
  scene.image.height = 3;
  const nlohmann::json doc = nlohmann::json::parse(
      render_stats_json("raytrace", scene, RenderMode::Full, {0.1, 0.2, 0.3}, out));
  ReportInput in = sample_input("out");
  in.renderers[0].stats = stats;
  const nlohmann::json metrics = nlohmann::json::parse(metrics_json(in));
  for (const nlohmann::json* written : {&doc["stats"], &metrics["renderers"]["raster"]["stats"]}) {
    for (const auto& [name, value] : stats) {
      const nlohmann::json& v = (*written)[name];
      if (!std::isfinite(value)) {
        EXPECT_TRUE(v.is_null()) << name;
      } else if (counts.count(name)) {
        EXPECT_TRUE(v.is_number_integer()) << name << ": " << v.dump();
        EXPECT_EQ(v.get<double>(), value) << name;
      } else {
        EXPECT_TRUE(v.is_number_float()) << name << ": " << v.dump();
        EXPECT_EQ(v.get<double>(), value) << name;
      }
    }
  }
  EXPECT_TRUE(doc["peak_memory_bytes"].is_number_integer()) << doc["peak_memory_bytes"].dump();
  EXPECT_GT(doc["peak_memory_bytes"].get<double>(), 0.0);
  EXPECT_TRUE(doc["scene_mesh_bytes"].is_number_integer()) << doc["scene_mesh_bytes"].dump();
  EXPECT_TRUE(doc["width"].is_number_integer());
}

// Every stat every renderer reports in every mode is what stat_kind says: a count a whole
// number, so a new ratio stat cannot go out as a truncated integer (it must be declared).
TEST(StatsJson, EveryRendererCountsInWholeNumbers) {
  Scene scene = make_builtin_scene("cornell").value();
  scene.image.width = 32;
  scene.image.height = 24;
  for (const RendererInfo& info : renderers())
    for (RenderMode mode : {RenderMode::Visibility, RenderMode::Local, RenderMode::Full}) {
      RenderOptions options;
      options.mode = mode;
      std::unique_ptr<Renderer> r = make_renderer(info.name).value();
      Expected<RenderOutput> out = r->render(scene, options);
      ASSERT_TRUE(out.ok()) << info.name << ": " << out.error().message;
      for (const auto& [name, value] : out->stats) {
        if (stat_kind(name) == StatKind::Count && std::isfinite(value)) {
          EXPECT_EQ(value, std::floor(value))
              << info.name << " " << to_string(mode) << ": " << name << " is not a count";
        }
      }
    }
}

TEST(MetricsJson, InfiniteAndNanValuesStayValidJson) {
  ReportInput in = sample_input("out");
  in.metrics.colour.psnr_db = std::numeric_limits<double>::infinity();
  in.metrics.depth.max_rel_error = std::numeric_limits<double>::quiet_NaN();
  in.renderers[0].stats["weird"] = std::numeric_limits<double>::infinity();
  std::string text = metrics_json(in);
  // No bare inf or nan where a value goes (after ':', ',' or '['); keys such as "info" are fine.
  auto bare_value = [&](const std::string& word) {
    for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
      size_t before = text.find_last_not_of(" \n-", at == 0 ? 0 : at - 1);
      if (before != std::string::npos && std::string(":,[").find(text[before]) != std::string::npos)
        return true;
    }
    return false;
  };
  EXPECT_FALSE(bare_value("inf")) << text;
  EXPECT_FALSE(bare_value("nan")) << text;
  EXPECT_FALSE(bare_value("Infinity")) << text;
  EXPECT_FALSE(bare_value("NaN")) << text;
  auto doc = nlohmann::json::parse(text);  // throws when invalid
  EXPECT_EQ(doc["color"]["psnr_db"], 999.0);
  EXPECT_TRUE(doc["depth"]["max_rel_error"].is_null());
  EXPECT_TRUE(doc["renderers"]["raster"]["stats"]["weird"].is_null());
}

TEST(MetricsJson, LodBlockOnlyWhenSomePixelIsTexturedInBoth) {
  ReportInput in = sample_input("out");
  auto plain = nlohmann::json::parse(metrics_json(in));
  EXPECT_FALSE(plain.contains("lod"));
  EXPECT_FALSE(plain["pairs"][0].contains("lod"));
  in.metrics.lod = {1234, 0.0625, 0.375};
  auto doc = nlohmann::json::parse(metrics_json(in));
  EXPECT_EQ(doc["lod"]["pixels"], 1234);
  EXPECT_EQ(doc["lod"]["mean_abs"], 0.0625);
  EXPECT_EQ(doc["lod"]["p99_abs"], 0.375);
  EXPECT_EQ(doc["pairs"][0]["lod"], doc["lod"]);
}

TEST_F(ReportDir, LodRowsBesideTheColourOnesWhenTextured) {
  ReportInput in = sample_input(dir_.string());
  auto plain = report_html(in);
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  EXPECT_EQ(plain->find("<code>p99_abs</code>"), std::string::npos);
  in.metrics.lod = {1234, 0.0625, 0.375};
  auto html = report_html(in);
  ASSERT_TRUE(html.ok()) << html.error().message;
  EXPECT_NE(html->find("<code>mean_abs</code></td><td class=\"num\">0.0625<"), std::string::npos);
  EXPECT_NE(html->find("<code>p99_abs</code></td><td class=\"num\">0.375<"), std::string::npos);
  EXPECT_NE(html->find("1234 pixels textured in both"), std::string::npos);
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
  // Both renders (side by side and in the flip view), diff.png, id_mismatch.png,
  // depth_diff.png, mismatch_classes.png and the cost picture of the renderer that has one.
  EXPECT_EQ(count_of(h, "data:image/png;base64,"), 9u);
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
  for (const char* word : {"id_agreement", "covered_fraction", "mismatch_classes.occlusion",
                           "max_rel_error", "psnr_db", "ssim", "time.render", "time.build",
                           "diff.png", "id_mismatch.png", "depth_diff.png", "mismatch_classes.png",
                           "raytrace: nearly all &lt;background&gt;", "depth_precision: both hit"})
    EXPECT_NE(h.find(word), std::string::npos) << word;
  EXPECT_NE(h.find("</html>"), std::string::npos);
}

// The depth outliers: ringed on depth_diff.png at their pixel centres (orange at a
// silhouette, blue on an analytic sphere, red elsewhere) in the image's own coordinates, and
// listed in a table where only the real disagreements are marked bad.
TEST_F(ReportDir, DepthOutliersAreRingedAndListed) {
  auto html = report_html(sample_input(dir_.string()));
  ASSERT_TRUE(html.ok()) << html.error().message;
  const std::string& h = html.value();
  const std::string marks = svg_with_class(h, "marks");
  ASSERT_FALSE(marks.empty());
  EXPECT_NE(marks.find("viewBox=\"0 0 8 6\""), std::string::npos) << marks;
  EXPECT_NE(marks.find("<circle cx=\"5.5\" cy=\"4.5\""), std::string::npos) << marks;
  EXPECT_NE(marks.find("<circle cx=\"1.5\" cy=\"2.5\""), std::string::npos) << marks;
  EXPECT_EQ(count_of(marks, "stroke=\"#ff1744\""), 1u);  // the one elsewhere
  EXPECT_EQ(count_of(marks, "stroke=\"#ff9f1c\""), 1u);  // the silhouette one
  EXPECT_EQ(count_of(marks, "stroke=\"#4dabf7\""), 1u);  // the analytic sphere's
  EXPECT_NE(h.find("7 pixels differ in depth by more than 1e-3 (relative): 2 on an object's "
                   "outline, 4 on analytic spheres, 1 elsewhere"),
            std::string::npos);
  EXPECT_NE(h.find("<tr><td class=\"num\">5</td><td class=\"num\">4</td><td class=\"num\">7"
                   "</td><td class=\"num\">2.5</td><td class=\"num\">2.51</td><td class=\"num "
                   "bad\">0.0035</td><td><span class=\"sw\" style=\"background:#ff1744\">"
                   "</span>elsewhere</td></tr>"),
            std::string::npos);
  EXPECT_NE(h.find("<td class=\"num\">0.0011</td><td><span class=\"sw\" "
                   "style=\"background:#4dabf7\"></span>analytic_sphere</td>"),
            std::string::npos);
  for (const char* word : {"p99_rel_error", "p999_rel_error", "outliers_elsewhere"})
    EXPECT_NE(h.find(word), std::string::npos) << word;
}

// Outliers on analytic spheres are expected (the z-buffer's polygon): their count is never
// flagged, while any outlier elsewhere is, as a real disagreement.
TEST_F(ReportDir, OnlyOutliersElsewhereAreFlagged) {
  ReportInput in = sample_input(dir_.string());
  auto row = [](const std::string& html, const std::string& metric) {
    const size_t at = html.find("<code>" + metric + "</code>");
    return at == std::string::npos ? std::string() : html.substr(at, html.find("</tr>", at) - at);
  };
  in.metrics.depth.outliers_elsewhere = 0;
  auto expected = report_html(in);
  ASSERT_TRUE(expected.ok()) << expected.error().message;
  EXPECT_NE(row(*expected, "outliers_on_analytic_spheres").find("class=\"num\">4<"),
            std::string::npos)
      << row(*expected, "outliers_on_analytic_spheres");
  EXPECT_NE(row(*expected, "outliers_elsewhere").find("class=\"num\">0<"), std::string::npos);
  in.metrics.depth.outliers_elsewhere = 1;
  auto real = report_html(in);
  ASSERT_TRUE(real.ok());
  EXPECT_NE(row(*real, "outliers_elsewhere").find("class=\"num bad\">1<"), std::string::npos)
      << row(*real, "outliers_elsewhere");
  EXPECT_EQ(row(*real, "outliers_on_analytic_spheres").find("bad"), std::string::npos);
}

// A long listing of outliers shows its first 10 rows; the rest are folded away in a
// <details>, still in the page.
TEST_F(ReportDir, LongOutlierListingIsFoldedAfterTenRows) {
  ReportInput in = sample_input(dir_.string());
  in.metrics.depth.worst_outliers.clear();
  for (int k = 0; k < 100; ++k)
    in.metrics.depth.worst_outliers.push_back(
        {k % 8, k / 8 % 6, 6, 0.01 - 1e-5 * k, 4.0f, 4.04f, DepthOutlierCause::Silhouette});
  in.metrics.depth.outliers = 295;
  auto html = report_html(in);
  ASSERT_TRUE(html.ok()) << html.error().message;
  const std::string& h = html.value();
  const size_t table = h.find("<h2>Depth outliers</h2>");
  const size_t fold =
      h.find("<details class=\"more-outliers\"><summary>The other 90 listed", table);
  ASSERT_NE(table, std::string::npos);
  ASSERT_NE(fold, std::string::npos) << "no fold after the first rows";
  const size_t end = h.find("</details>", fold);
  EXPECT_EQ(count_of(h.substr(table, fold - table), ">silhouette</td></tr>"), 10u);
  EXPECT_EQ(count_of(h.substr(fold, end - fold), ">silhouette</td></tr>"), 90u);
  // Ten or fewer: no fold.
  in.metrics.depth.worst_outliers.resize(10);
  auto short_listing = report_html(in);
  ASSERT_TRUE(short_listing.ok());
  EXPECT_EQ(short_listing->find("<details class=\"more-outliers\""), std::string::npos);
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

// The SVG of an element with this id, from its opening tag to the next </svg>.
std::string svg_with_id(const std::string& html, const std::string& id) {
  const size_t named = html.find(" id=\"" + id + "\"");
  if (named == std::string::npos) return "";
  const size_t at = html.rfind("<svg", named);
  if (at == std::string::npos || html.find('>', at) < named) return "";
  size_t end = html.find("</svg>", at);
  return end == std::string::npos ? "" : html.substr(at, end + 6 - at);
}

TEST_F(ReportDir, DepthDifferenceWithItsScale) {
  ReportInput in = sample_input(dir_.string());
  in.depth_diff_scale = {1e-5f, 1e-2f};
  auto html = report_html(in);
  ASSERT_TRUE(html.ok()) << html.error().message;
  const std::string& h = html.value();
  std::ifstream file(dir_ / "depth_diff.png", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_NE(h.find("<img src=\"data:image/png;base64," + base64(bytes) +
                   "\" alt=\"relative depth difference\">"),
            std::string::npos);
  // The caption states the scale and the two background colours; the colour bar has a tick
  // per decade.
  EXPECT_NE(h.find("log scale</b>: black &le; 1e-5"), std::string::npos);
  EXPECT_NE(h.find("yellow-white &ge; 1e-2"), std::string::npos);
  EXPECT_NE(h.find("background in both"), std::string::npos);
  EXPECT_NE(h.find("background in one, a hit in the other"), std::string::npos);
  for (const char* tick : {">1e-5</text>", ">1e-4</text>", ">1e-3</text>", ">1e-2</text>"})
    EXPECT_NE(h.find(tick), std::string::npos) << tick;
  auto doc = nlohmann::json::parse(metrics_json(in));
  EXPECT_EQ(doc["files"]["depth_diff"], "depth_diff.png");
  EXPECT_EQ(doc["depth_diff_scale"]["low"].get<double>(), 1e-5);
  EXPECT_EQ(doc["depth_diff_scale"]["high"].get<double>(), 1e-2);
  fs::remove(dir_ / "depth_diff.png");
  auto missing = report_html(in);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("depth_diff.png"), std::string::npos);
}

TEST_F(ReportDir, TimingChartHasEveryPhaseOfEveryRenderer) {
  ReportInput in = sample_input(dir_.string());
  in.renderers[0].stats = {{"time.load", 0.002},
                           {"time.setup", 0.01},
                           {"time.upload", 0.02},
                           {"time.render", 0.05},
                           {"time.readback", 0.01}};
  in.renderers[0].seconds = 0.12;  // 0.03 s in no phase: "other"
  in.renderers[1].stats = {
      {"time.load", 0.002}, {"time.build", 0.05}, {"time.bvh_build", 0.04}, {"time.render", 0.35}};
  in.renderers[1].seconds = 0.4;  // every bit in a phase: no "other"
  auto html = report_html(in);
  ASSERT_TRUE(html.ok()) << html.error().message;
  const std::string svg = svg_with_id(html.value(), "timing-chart");
  ASSERT_FALSE(svg.empty());
  EXPECT_NE(svg.find("role=\"img\""), std::string::npos);
  EXPECT_NE(svg.find("<title id=\"timing-chart-title\">"), std::string::npos);

  auto row = [&](const std::string& name) {
    size_t at = svg.find("<g class=\"bar-row\" data-renderer=\"" + name + "\">");
    if (at == std::string::npos) return std::string();
    return svg.substr(at, svg.find("</g>", at) - at);
  };
  const std::string raster = row("raster"), raytrace = row("raytrace");
  ASSERT_FALSE(raster.empty());
  ASSERT_FALSE(raytrace.empty());
  for (const char* phase : {"load", "setup", "upload", "render", "readback", "other"})
    EXPECT_NE(raster.find(std::string("data-phase=\"") + phase + "\""), std::string::npos) << phase;
  for (const char* phase : {"load", "build", "render"})
    EXPECT_NE(raytrace.find(std::string("data-phase=\"") + phase + "\""), std::string::npos)
        << phase;
  // Nested in time.build, so not stacked a second time; named in the build tooltip instead.
  EXPECT_EQ(raytrace.find("data-phase=\"bvh_build\""), std::string::npos);
  EXPECT_NE(raytrace.find("build 0.05 s (of which bvh_build 0.04 s)"), std::string::npos);
  EXPECT_EQ(raytrace.find("data-phase=\"other\""), std::string::npos);
  // Seconds per segment (tooltips) and the bar totals: load plus the render call.
  EXPECT_NE(raster.find("raster: upload 0.02 s"), std::string::npos);
  EXPECT_NE(raster.find("raster: other 0.03 s"), std::string::npos);
  EXPECT_NE(raster.find(">0.122 s</text>"), std::string::npos);
  EXPECT_NE(raytrace.find(">0.402 s</text>"), std::string::npos);
  // Pipeline order within a bar: load, setup, upload, render, readback, other.
  size_t last = 0;
  for (const char* phase : {"load", "setup", "upload", "render", "readback", "other"}) {
    size_t at = raster.find(std::string("data-phase=\"") + phase + "\"");
    EXPECT_GT(at, last) << phase;
    last = at;
  }
  // The same numbers as text for screen readers.
  EXPECT_NE(svg.find("<desc id=\"timing-chart-desc\">raster: load 0.002 s, setup 0.01 s"),
            std::string::npos);
}

// The hybrid's bar splits into its z-buffer passes and its traced rays; the tracer's centre
// pass (time.render) is part of time.trace and is not stacked twice.
TEST_F(ReportDir, TimingChartSplitsTheHybridIntoZBufferAndTrace) {
  ReportInput in = sample_input(dir_.string());
  in.renderers[1].name = "hybrid";
  in.renderers[1].stats = {{"time.load", 0.002},  {"time.build", 0.01},
                           {"time.zbuffer", 0.2}, {"time.trace", 0.3},
                           {"time.render", 0.25}, {"zbuffer.time.raster", 0.1}};
  in.renderers[1].seconds = 0.51;  // build + zbuffer + trace: no "other"
  auto html = report_html(in);
  ASSERT_TRUE(html.ok()) << html.error().message;
  const std::string svg = svg_with_id(html.value(), "timing-chart");
  size_t at = svg.find("<g class=\"bar-row\" data-renderer=\"hybrid\">");
  ASSERT_NE(at, std::string::npos);
  const std::string bar = svg.substr(at, svg.find("</g>", at) - at);
  size_t last = 0;
  for (const char* phase : {"load", "build", "zbuffer", "trace"}) {
    size_t found = bar.find(std::string("data-phase=\"") + phase + "\"");
    ASSERT_NE(found, std::string::npos) << phase;
    EXPECT_GT(found, last) << phase << " out of pipeline order";
    last = found;
  }
  EXPECT_EQ(bar.find("data-phase=\"render\""), std::string::npos);
  EXPECT_EQ(bar.find("data-phase=\"other\""), std::string::npos);
  EXPECT_NE(bar.find("hybrid: trace 0.3 s (of which render 0.25 s)"), std::string::npos);
  EXPECT_NE(bar.find(">0.512 s</text>"), std::string::npos);  // load + the render call
}
