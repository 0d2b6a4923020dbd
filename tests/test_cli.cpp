// The rvr command line, run as a user runs it: exit codes 0/1/2/3, outputs, and nothing
// written when the input is bad.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <compare>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "model_corpus.h"
#include "rvr/core/expected.h"
#include "rvr/core/render_option_table.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/present/html_escape.h"

namespace fs = std::filesystem;

namespace {

struct RunResult {
  int status = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("rvr_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
         "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  RunResult run(const std::string& args, const std::string& env = "") {
    fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    // Bounded: a hang ends as status 124 (timeout's) instead of stalling the suite.
    std::string cmd = env + " timeout -k 10 " + std::to_string(RVR_PROCESS_TIMEOUT) + " " +
                      std::string(RVR_BINARY) + " " + args + " >" + out.string() + " 2>" +
                      err.string() + " </dev/null";
    int raw = std::system(cmd.c_str());
    RunResult r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    fs::remove(out);
    fs::remove(err);
    return r;
  }

  fs::path write(const std::string& name, const std::string& text) {
    fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }

  // Files in the test folder other than the inputs we wrote.
  std::vector<std::string> outputs(const std::vector<std::string>& inputs) {
    std::vector<std::string> found;
    for (const auto& e : fs::recursive_directory_iterator(dir_)) {
      std::string name = e.path().filename().string();
      if (std::find(inputs.begin(), inputs.end(), name) == inputs.end()) found.push_back(name);
    }
    return found;
  }

  fs::path dir_;
};

const char* kSmall = "--width 80 --height 60";

}  // namespace

TEST_F(Cli, ScenesListsEveryBuiltin) {
  RunResult r = run("scenes");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* name : {"builtin:cornell", "builtin:spheres", "builtin:occluders:N",
                           "builtin:soup:N", "builtin:tessphere:N"})
    EXPECT_NE(r.out.find(name), std::string::npos) << name;
}

TEST_F(Cli, RenderWritesImageAovsAndStats) {
  fs::path out = dir_ / "sub" / "img.png";
  RunResult r =
      run("render builtin:cornell -r raytrace " + std::string(kSmall) + " -o " + out.string() +
          " --aov depth,id,normal,cost --stats " + (dir_ / "stats.json").string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f :
       {"img.png", "img.depth.exr", "img.id.exr", "img.normal.exr", "img.cost.exr", "img.cost.png"})
    EXPECT_TRUE(fs::exists(dir_ / "sub" / f)) << f;
  nlohmann::json stats = nlohmann::json::parse(slurp(dir_ / "stats.json"));
  EXPECT_EQ(stats["renderer"], "raytrace");
  // The box's open front leaves rows of background outside the scene's screen bounds: culled
  // without rays; with the rays made, the pixel count.
  EXPECT_GT(stats["stats"]["rays.primary"].get<double>(), 0.0);
  EXPECT_GT(stats["stats"]["rays.primary_culled"].get<double>(), 0.0);
  EXPECT_EQ(stats["stats"]["rays.primary"].get<double>() +
                stats["stats"]["rays.primary_culled"].get<double>(),
            80 * 60);
  EXPECT_TRUE(stats["time"].contains("render"));
  EXPECT_TRUE(stats["time"].contains("load"));
  EXPECT_TRUE(stats["time"].contains("write"));
  EXPECT_GT(stats["peak_memory_bytes"].get<double>(), 0.0);
}

// "-" is standard output, as tools read it: the JSON on stdout, no file named "-" anywhere.
TEST_F(Cli, StatsDashPrintsTheJsonOnStandardOutput) {
  RunResult r = run("render builtin:spheres -r raytrace --mode local " + std::string(kSmall) +
                    " -o " + (dir_ / "s.png").string() + " --stats - --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json stats = nlohmann::json::parse(r.out);
  EXPECT_EQ(stats["renderer"], "raytrace");
  EXPECT_EQ(stats["width"], 80);
  EXPECT_FALSE(fs::exists("-"));
  EXPECT_FALSE(fs::exists(dir_ / "-"));
}

TEST_F(Cli, RasterRenders) {
  RunResult r = run("render builtin:spheres -r raster --mode local " + std::string(kSmall) +
                    " -o " + (dir_ / "r.exr").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "r.exr"));
}

TEST_F(Cli, BadSceneIsExit2WithOneErrorLineAndNoOutput) {
  fs::path scene =
      write("bad.json", R"({"camera": {"eye": [0,0,5], "target": [0,0,0], "up": [0,1,0]},
    "objects": [{"type": "sphere", "center": [0,0,0], "radius": -1}]})");
  RunResult r = run("render " + scene.string() + " -r raytrace -o " + (dir_ / "out.png").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("objects[0].radius"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(outputs({"bad.json"}).empty());
}

TEST_F(Cli, SyntaxErrorNamesLineAndColumn) {
  fs::path scene = write(
      "syntax.json", "{\n  \"camera\": {\n    \"eye\": [0, 0, 5]\n    \"target\": [0,0,0]\n}\n");
  RunResult r = run("compare " + scene.string() + " -o " + (dir_ / "cmp").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("syntax.json:4:"), std::string::npos) << r.err;
  EXPECT_TRUE(outputs({"syntax.json"}).empty());
}

TEST_F(Cli, BadUsageIsExit2) {
  EXPECT_EQ(run("render -r nosuch -o " + (dir_ / "x.png").string()).status, 2);
  EXPECT_EQ(run("render builtin:nosuch -r raytrace -o " + (dir_ / "x.png").string()).status, 2);
  EXPECT_EQ(run("render builtin:soup:0 -r raytrace -o " + (dir_ / "x.png").string()).status, 2);
  EXPECT_EQ(run("render -r raytrace --mode fancy").status, 2);
  EXPECT_EQ(run("render -r raytrace --width 0").status, 2);
  EXPECT_EQ(run("frobnicate").status, 2);
  EXPECT_EQ(run("").status, 2);
  EXPECT_EQ(run("render " + (dir_ / "missing.json").string() + " -r raytrace").status, 2);
  EXPECT_TRUE(outputs({}).empty());
}

// The model-file options: --up, --camera, --lights and --exposure reach the scene (the
// exported scene shows them), and bad values are exit 2 with one error line.
TEST_F(Cli, ModelUpCameraLightsAndExposureOptions) {
  fs::path obj = write("zup.obj", "v 0 0 0\nv 1 0 0\nv 0 1 2\nf 1 2 3\n");
  RunResult r =
      run("render " + obj.string() + " -r raytrace " + kSmall +
          " --up z --camera auto --lights auto --exposure 1 -o " + (dir_ / "z.png").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "z.png"));
  // Exported, a model file's automatic exposure is kept in the scene (a white triangle under
  // the default key light: below 0).
  write("white.mtl", "newmtl white\nKd 1 1 1\n");
  fs::path white =
      write("white.obj", "mtllib white.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl white\nf 1 2 3\n");
  r = run("scenes --export " + white.string() + " -o " + (dir_ / "white.json").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(dir_ / "white.json").find("\"exposure\": -"), std::string::npos);
  // --exposure reaches the renderer: the linear EXR at --exposure 1 is exactly twice the one
  // at 0, pixel by pixel; --up z turns the model (another image from --up y).
  auto exr = [&](const std::string& args, const char* name) {
    RunResult rr = run("render " + obj.string() + " -r raytrace " + kSmall + " --mode local " +
                       args + " -o " + (dir_ / name).string());
    EXPECT_EQ(rr.status, 0) << rr.err;
    return rvr::read_image((dir_ / name).string()).value();
  };
  rvr::Image e0 = exr("--exposure 0", "e0.exr"), e1 = exr("--exposure 1", "e1.exr");
  ASSERT_EQ(e0.pixels.size(), e1.pixels.size());
  float brightest = 0.0f;
  for (size_t i = 0; i < e0.pixels.size(); ++i) {
    ASSERT_EQ(e1.pixels[i], 2.0f * e0.pixels[i]) << i;
    brightest = std::max(brightest, e0.pixels[i]);
  }
  EXPECT_GT(brightest, 0.0f);
  EXPECT_NE(exr("--up y", "y.exr").pixels, exr("--up z", "z.exr").pixels);
  for (const char* bad :
       {"--up w", "--camera fancy", "--lights none", "--exposure 65", "--exposure nan"}) {
    SCOPED_TRACE(bad);
    r = run("render " + obj.string() + " -r raytrace " + bad + " -o " + (dir_ / "b.png").string());
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "b.png"));
  }
}

TEST_F(Cli, SoftpipeIsRefusedWithExit3) {
  RunResult r = run("render builtin:cornell -r raster " + std::string(kSmall) + " -o " +
                        (dir_ / "x.png").string(),
                    "GALLIUM_DRIVER=softpipe");
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("softpipe"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));
}

// builtin:soup:3000 at 160x120 (local mode), raster (llvmpipe) against raytrace: of 19,200
// pixels the two disagree on 10 (agreement 0.99948), all of class edge (7 on edges shared by two
// triangles, 3 on silhouettes). They are rule ties: llvmpipe snaps vertices to 1/256 px (8
// subpixel bits), which moves an edge by up to 1/512 px, and a pixel centre closer than that to
// an edge may fall on the other side of it than the tracer's float test puts it. Their number is
// the visible edge length times that distance, so it varies with the driver's snapping and
// set-up order only: kMaxSoupEdgeTies allows twice the 10 measured. A mismatch of any other
// class is a real disagreement.
constexpr int kSoupPixels = 160 * 120;
constexpr int kMaxSoupEdgeTies = 2 * 10;

TEST_F(Cli, CompareWritesEverythingAndThresholdGivesExit1) {
  fs::path out = dir_ / "cmp";
  const std::string cmp = "compare builtin:soup:3000 --width 160 --height 120 -o ";
  RunResult r = run(cmp + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"raster.png", "raytrace.png", "diff.png", "id_mismatch.png",
                        "depth_diff.png", "metrics.json", "report.html"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  nlohmann::json m = nlohmann::json::parse(slurp(out / "metrics.json"));
  for (const char* key :
       {"scene", "width", "height", "mode", "renderers", "visibility", "depth", "color"})
    EXPECT_TRUE(m.contains(key)) << key;
  EXPECT_NE(r.out.find("id agreement"), std::string::npos);

  // What was compared, and the files it wrote, as metrics.json names them: every one exists,
  // and every file written is named.
  EXPECT_EQ(m["compared"], nlohmann::json({"raster", "raytrace"}));
  ASSERT_EQ(m["pairs"].size(), 1u);
  EXPECT_EQ(m["pairs"][0]["compared"], m["compared"]);
  std::set<std::string> named;
  for (const auto& [kind, file] : m["files"].items()) {
    EXPECT_TRUE(fs::exists(out / file.get<std::string>())) << kind << ": " << file;
    named.insert(file.get<std::string>());
  }
  for (const auto& [name, renderer] : m["renderers"].items()) {
    EXPECT_TRUE(fs::exists(out / renderer["image"].get<std::string>())) << name;
    named.insert(renderer["image"].get<std::string>());
    if (renderer.contains("cost")) {
      EXPECT_TRUE(fs::exists(out / renderer["cost"]["image"].get<std::string>())) << name;
      named.insert(renderer["cost"]["image"].get<std::string>());
    }
    // Local shading of triangles needs nothing either renderer lacks: no warnings.
    EXPECT_TRUE(renderer["warnings"].is_array() && renderer["warnings"].empty())
        << name << ": " << renderer["warnings"];
  }
  named.insert("metrics.json");
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_TRUE(named.count(e.path().filename().string())) << e.path() << " is not in files";
  // The summary's "wrote DIR/{...}" names every file written, the cost pictures included.
  const std::string wrote = "  wrote " + out.string() + "/{";
  const size_t from = r.out.find(wrote), to = r.out.find("}\n", from);
  ASSERT_TRUE(from != std::string::npos && to != std::string::npos) << r.out;
  std::set<std::string> listed;
  std::stringstream list(r.out.substr(from + wrote.size(), to - from - wrote.size()));
  for (std::string file; std::getline(list, file, ',');) listed.insert(file);
  std::set<std::string> written;
  for (const auto& e : fs::directory_iterator(out)) written.insert(e.path().filename().string());
  EXPECT_EQ(listed, written) << r.out;
  EXPECT_TRUE(m["warnings"].is_array() && m["warnings"].empty()) << m["warnings"];

  // The measured agreement, and every mismatch an edge tie.
  const auto& v = m["visibility"];
  const int mismatched = v["mismatched_pixels"].get<int>();
  std::printf("soup:3000 160x120 raster vs raytrace: id agreement %.5f, %d mismatched (%d edge)\n",
              v["id_agreement"].get<double>(), mismatched,
              v["mismatch_classes"]["edge"].get<int>());
  EXPECT_EQ(v["pixels"].get<int>(), kSoupPixels);
  EXPECT_DOUBLE_EQ(v["id_agreement"].get<double>(), double(kSoupPixels - mismatched) / kSoupPixels);
  EXPECT_EQ(v["mismatch_classes"]["edge"].get<int>(), mismatched);
  EXPECT_LE(mismatched, kMaxSoupEdgeTies);
  EXPECT_GE(v["id_agreement"].get<double>(), 1.0 - double(kMaxSoupEdgeTies) / kSoupPixels);

  // --fail-below-agreement on both sides of the measured agreement A = (N - k) / N: F = A is not
  // below (exit 0); one pixel more agreement than measured is (exit 1); one fewer is not.
  auto gate = [&](int agreeing, const std::string& name) {
    char f[64];
    std::snprintf(f, sizeof f, "%.17g", double(agreeing) / kSoupPixels);
    return run(cmp + (dir_ / name).string() + " --fail-below-agreement " + f);
  };
  const int agreeing = kSoupPixels - mismatched;
  RunResult at = gate(agreeing, "at");
  EXPECT_EQ(at.status, 0) << at.err;
  RunResult above = gate(agreeing + 1, "above");
  EXPECT_EQ(above.status, 1) << above.err;
  EXPECT_NE(above.err.find("raster vs raytrace: id agreement"), std::string::npos) << above.err;
  RunResult below = gate(agreeing - 1, "below");
  EXPECT_EQ(below.status, 0) << below.err;
  // Outside 0 ... 1 is bad usage.
  RunResult over_one = run(cmp + (dir_ / "over").string() + " --fail-below-agreement 1.5");
  EXPECT_EQ(over_one.status, 2) << over_one.err;
}

// --fail-below-agreement on pairs whose agreement is known without rendering: raster (OpenGL)
// skips the csg scene's csg objects that the tracer draws, so they must disagree; a renderer
// against itself agrees exactly (1 is not below 1).
// The z-buffer draws builtin:csg's leaves as 3-longitude polyhedra, the tracer intersects the
// exact spheres: the silhouettes differ by a good share of each solid's pixels (measured
// agreement 0.926), and in front of the floor the z-buffer sees the floor where the tracer sees a
// solid (occlusion mismatches; measured 8), never the background (coverage 0).
const std::string kCoarseCsg = "compare builtin:csg --width 64 --height 48 --sphere-segments 3 ";

TEST_F(Cli, AgreementThresholdGivesExit1OnlyWhenCrossed) {
  const std::string csg = kCoarseCsg + "-r raster,raytrace ";
  RunResult below = run(csg + "--fail-below-agreement 0.95 -o " + (dir_ / "below").string());
  EXPECT_EQ(below.status, 1) << below.err;
  // The outputs are written all the same, and they show why.
  nlohmann::json m = nlohmann::json::parse(slurp(dir_ / "below" / "metrics.json"));
  EXPECT_LT(m["visibility"]["id_agreement"].get<double>(), 0.95);
  RunResult lenient = run(csg + "--fail-below-agreement 0 -o " + (dir_ / "lenient").string());
  EXPECT_EQ(lenient.status, 0) << lenient.err;
  RunResult none = run(csg + "-o " + (dir_ / "none").string());
  EXPECT_EQ(none.status, 0) << none.err;
  RunResult itself =
      run("compare builtin:cornell -r raytrace,raytrace --width 64 --height 48 "
          "--fail-below-agreement 1 -o " +
          (dir_ / "itself").string());
  EXPECT_EQ(itself.status, 0) << itself.err;
}

// Nothing visible is not agreement: a unit sphere 4 to 6 in front of the eye with the near plane
// at 10 leaves every pixel background in both renders, which agree on every pixel (id agreement
// 1). The comparison says so: covered fraction 0, a warning in metrics.json and report.html, and
// --fail-below-agreement fails whatever F.
TEST_F(Cli, NothingVisibleWarnsAndFailsTheAgreementThreshold) {
  for (const char* camera : {R"("near": 10, "far": 100)", R"("near": 0.1, "far": 100)"}) {
    SCOPED_TRACE(camera);
    // The second camera looks away from the sphere, which lies behind it.
    const std::string target =
        std::string(camera).find("0.1") != std::string::npos ? "[0, 0, 10]" : "[0, 0, 0]";
    fs::path scene = write(
        "empty.json",
        R"({"camera": {"eye": [0, 0, 5], "target": )" + target + R"(, "up": [0, 1, 0], )" + camera +
            R"(}, "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}]})");
    const std::string cmp =
        "compare " + scene.string() + " -r softraster,raytrace --width 32 --height 24 -o ";
    RunResult plain = run(cmp + (dir_ / "plain").string());
    EXPECT_EQ(plain.status, 0) << plain.err;
    EXPECT_NE(plain.err.find("nothing visible"), std::string::npos) << plain.err;
    nlohmann::json m = nlohmann::json::parse(slurp(dir_ / "plain" / "metrics.json"));
    EXPECT_EQ(m["format"], "rvr-metrics/2");
    EXPECT_EQ(m["visibility"]["id_agreement"].get<double>(), 1.0);
    EXPECT_EQ(m["visibility"]["covered_fraction"].get<double>(), 0.0);
    EXPECT_EQ(m["visibility"]["covered_agreement"].get<double>(), 0.0);
    ASSERT_EQ(m["warnings"].size(), 2u);  // one per renderer
    for (const auto& w : m["warnings"])
      EXPECT_NE(w.get<std::string>().find("nothing visible"), std::string::npos) << w;
    EXPECT_NE(slurp(dir_ / "plain" / "report.html").find("nothing visible"), std::string::npos);
    RunResult gated = run(cmp + (dir_ / "gated").string() + " --fail-below-agreement 0");
    EXPECT_EQ(gated.status, 1) << gated.err;
    EXPECT_NE(gated.err.find("nothing visible"), std::string::npos) << gated.err;
    fs::remove_all(dir_ / "plain");
    fs::remove_all(dir_ / "gated");
  }
}

// Every scene loader warning reaches metrics.json (`warnings`), report.html and render --stats
// beside the renderers', and stderr once: an STL whose facet normals contradict the winding,
// with a zero-area facet (tests/model_corpus.h), and a textured OBJ whose texture file is
// missing.
TEST_F(Cli, LoaderWarningsReachMetricsReportAndStats) {
  fs::path stl = write("stated.stl", rvr::test::corpus::ascii_stl_cube_with_stated_normals(true));
  fs::path obj = write("tex.obj",
                       "mtllib tex.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\n"
                       "vt 1 1\nvt 0 1\nusemtl paint\nf 1/1 2/2 3/3 4/4\n");
  write("tex.mtl", "newmtl paint\nKd 0.8 0.5 0.2\nmap_Kd wood.png\n");
  struct Case {
    fs::path file;
    std::vector<std::string> warnings;  // each starts with the file's path
  };
  for (const Case& c : {Case{stl,
                             {": 5 facets have normals that contradict the winding",
                              ": dropped 1 degenerate triangle"}},
                        Case{obj, {": material 'paint': texture 'wood.png' not found"}}}) {
    SCOPED_TRACE(c.file.string());
    fs::path out = dir_ / "cmp", stats = dir_ / "stats.json";
    RunResult cmp = run("compare " + c.file.string() +
                        " -r softraster,raytrace --width 32 --height 24 -o " + out.string());
    ASSERT_EQ(cmp.status, 0) << cmp.err;
    RunResult render = run("render " + c.file.string() + " -r raytrace --width 32 --height 24 -o " +
                           (dir_ / "r.png").string() + " --stats " + stats.string());
    ASSERT_EQ(render.status, 0) << render.err;
    nlohmann::json metrics = nlohmann::json::parse(slurp(out / "metrics.json"));
    nlohmann::json stat = nlohmann::json::parse(slurp(stats));
    std::string html = slurp(out / "report.html");
    for (const std::string& tail : c.warnings) {
      const std::string w = c.file.string() + tail;
      auto listed = [&](const nlohmann::json& list) {
        return std::count_if(list.begin(), list.end(), [&](const nlohmann::json& x) {
          return x.get<std::string>().rfind(w, 0) == 0;
        });
      };
      EXPECT_EQ(listed(metrics["warnings"]), 1) << metrics["warnings"];
      EXPECT_EQ(listed(stat["warnings"]), 1) << stat["warnings"];
      EXPECT_NE(html.find("<li>" + rvr::present::escape_html(w)), std::string::npos) << w;
      for (const std::string* err : {&cmp.err, &render.err}) {
        size_t first = err->find("warning: " + w);
        EXPECT_NE(first, std::string::npos) << *err;
        EXPECT_EQ(err->find("warning: " + w, first + 1), std::string::npos) << *err;
      }
    }
    fs::remove_all(out);
  }
}

// A model file whose only mesh is Assimp's placeholder for a file with a camera alone: bad
// input, one error line saying what the file holds, nothing written.
TEST_F(Cli, ModelWithOnlyACameraIsExit2NoTriangles) {
  fs::path dae = write("camera.dae", rvr::test::corpus::dae_camera_only(false));
  for (const char* command : {"render", "compare"}) {
    SCOPED_TRACE(command);
    RunResult r = run(std::string(command) + " " + dae.string() + " -r raytrace" +
                      (command[0] == 'c' ? ",softraster " : " ") + kSmall + " -o " +
                      (dir_ / (command[0] == 'r' ? "out.png" : "cmp")).string());
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err, "error: " + dae.string() +
                         ": objects: no triangles (the file holds only 1 camera)\n");
    EXPECT_TRUE(outputs({"camera.dae"}).empty());
  }
}

// Every pair of three renderers is compared, the first pair also at the top level; --fail-on
// fails on the chosen classes only. raster (OpenGL) skips builtin:csg's csg objects, which the
// tracers draw in front of the floor and wall: raster shows those farther surfaces there,
// occlusion mismatches and no coverage ones (something lies behind every csg pixel); raytrace
// against itself has none.
TEST_F(Cli, EveryPairIsComparedAndFailOnChoosesClasses) {
  const std::string csg = kCoarseCsg;
  fs::path out = dir_ / "three";
  RunResult r = run(csg + "-r raster,raytrace,raytrace --mode full -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json m = nlohmann::json::parse(slurp(out / "metrics.json"));
  ASSERT_EQ(m["pairs"].size(), 3u);
  EXPECT_EQ(m["pairs"][0]["compared"], nlohmann::json({"raster", "raytrace"}));
  EXPECT_EQ(m["pairs"][1]["compared"], nlohmann::json({"raster", "raytrace-2"}));
  EXPECT_EQ(m["pairs"][2]["compared"], nlohmann::json({"raytrace", "raytrace-2"}));
  EXPECT_EQ(m["pairs"][0]["visibility"], m["visibility"]);
  EXPECT_EQ(m["pairs"][2]["visibility"]["id_agreement"].get<double>(), 1.0);
  EXPECT_GT(m["visibility"]["mismatch_classes"]["occlusion"].get<int>(), 0);
  EXPECT_EQ(m["visibility"]["mismatch_classes"]["coverage"].get<int>(), 0);
  for (const auto& pair : m["pairs"])
    for (const auto& [kind, file] : pair["files"].items())
      EXPECT_TRUE(fs::exists(out / file.get<std::string>())) << file;
  EXPECT_NE(r.out.find("raytrace vs raytrace-2"), std::string::npos) << r.out;
  // A renderer compared twice writes its image under its own key.
  EXPECT_EQ(m["renderers"]["raytrace"]["image"], "raytrace.png");
  EXPECT_EQ(m["renderers"]["raytrace-2"]["image"], "raytrace-2.png");
  EXPECT_TRUE(fs::exists(out / "raytrace-2.png"));
  // Every renderer draws every effect of builtin:csg (CSG solids and their shadows): no warning.
  EXPECT_TRUE(m["renderers"]["raster"]["warnings"].empty()) << m["renderers"]["raster"];
  EXPECT_TRUE(m["renderers"]["raytrace"]["warnings"].empty());
  EXPECT_TRUE(m["renderers"]["raytrace-2"]["warnings"].empty());

  RunResult occlusion = run(csg + "-r raster,raytrace --fail-on occlusion,coverage -o " +
                            (dir_ / "occlusion").string());
  EXPECT_EQ(occlusion.status, 1) << occlusion.err;
  EXPECT_NE(occlusion.err.find("occlusion mismatches"), std::string::npos) << occlusion.err;
  RunResult coverage =
      run(csg + "-r raster,raytrace --fail-on coverage -o " + (dir_ / "coverage").string());
  EXPECT_EQ(coverage.status, 0) << coverage.err;
  RunResult same = run(csg +
                       "-r raytrace,raytrace --fail-on edge,depth_precision,occlusion,"
                       "coverage -o " +
                       (dir_ / "same").string());
  EXPECT_EQ(same.status, 0) << same.err;
  RunResult bad = run(csg + "--fail-on visibility -o " + (dir_ / "bad").string());
  EXPECT_EQ(bad.status, 2) << bad.err;
}

namespace {

// Binary PPM (P6) of `width` x `width` black pixels but the first `white` ones.
void write_ppm(const fs::path& p, int width, int white) {
  std::ofstream out(p, std::ios::binary);
  out << "P6\n" << width << " " << width << "\n255\n";
  for (int i = 0; i < width * width; ++i)
    for (int c = 0; c < 3; ++c) out.put(i < white ? char(255) : char(0));
}

}  // namespace

// A pair whose difference is known in closed form: 10x10 pixels, one white pixel against black.
// Every channel of that pixel differs by 1, every other by 0: mean error 3/300 = 0.01, RMS error
// sqrt(3/300) = 0.1, one pixel (1%) over any threshold below 1. The thresholds are tried on both
// sides of those values, 1e-4 away from 0.1 (far beyond the rounding of a sum of 300 squares).
TEST_F(Cli, DiffReportsAndFailsAboveThreshold) {
  fs::path black = dir_ / "black.ppm", one = dir_ / "one.ppm";
  write_ppm(black, 10, 0);
  write_ppm(one, 10, 1);
  const std::string pair = "diff " + black.string() + " " + one.string();
  RunResult plain = run(pair + " -o " + (dir_ / "heat.png").string());
  EXPECT_EQ(plain.status, 1) << plain.err;  // idiff's default: any pixel over 1e-6 fails
  EXPECT_NE(plain.out.find("Mean error = 0.01\n"), std::string::npos) << plain.out;
  EXPECT_NE(plain.out.find("RMS error = 0.1\n"), std::string::npos) << plain.out;
  EXPECT_NE(plain.out.find("1 pixels (1%) over 1e-06"), std::string::npos) << plain.out;
  EXPECT_NE(plain.out.find("Max error  = 1 @ (0, 0, R)"), std::string::npos) << plain.out;
  EXPECT_NE(plain.out.find("\nFAILURE\n"), std::string::npos) << plain.out;
  EXPECT_TRUE(fs::exists(dir_ / "heat.png"));

  // The fail threshold on both sides of the one pixel's difference of 1.
  EXPECT_EQ(run(pair + " --fail 0.999 --warn 0.999").status, 1);
  EXPECT_EQ(run(pair + " --fail 1 --warn 1").status, 0);
  // The percentage on both sides of 1% (more than P% fails).
  EXPECT_EQ(run(pair + " --failpercent 0.99 --warnpercent 0.99").status, 1);
  EXPECT_EQ(run(pair + " --failpercent 1 --warnpercent 1").status, 0);
  // --fail-above on both sides of the RMS error 0.1, the pixel counts let through.
  const std::string allowed = pair + " --failpercent 1 --warnpercent 1 --fail-above ";
  RunResult above = run(allowed + "0.0999");
  EXPECT_EQ(above.status, 1) << above.out;
  EXPECT_NE(above.out.find("RMS error 0.1 above 0.0999"), std::string::npos) << above.out;
  EXPECT_NE(above.out.find("\nFAILURE\n"), std::string::npos) << above.out;
  RunResult under = run(allowed + "0.1001");
  EXPECT_EQ(under.status, 0) << under.out;
  EXPECT_NE(under.out.find("\nPASS\n"), std::string::npos) << under.out;

  // Rendered images: one against itself passes, two scenes fail with no threshold given, two
  // sizes cannot be compared.
  fs::path a = dir_ / "a.png", b = dir_ / "b.png", c = dir_ / "c.png";
  ASSERT_EQ(run("render builtin:cornell -r raytrace --mode local " + std::string(kSmall) + " -o " +
                a.string())
                .status,
            0);
  ASSERT_EQ(run("render builtin:spheres -r raytrace --mode local " + std::string(kSmall) + " -o " +
                b.string())
                .status,
            0);
  ASSERT_EQ(
      run("render builtin:cornell -r raytrace --mode local --width 40 --height 30 -o " + c.string())
          .status,
      0);
  RunResult same = run("diff " + a.string() + " " + a.string());
  EXPECT_EQ(same.status, 0) << same.err;
  EXPECT_NE(same.out.find("\nPASS\n"), std::string::npos) << same.out;
  RunResult differ = run("diff " + a.string() + " " + b.string());
  EXPECT_EQ(differ.status, 1) << differ.err;
  EXPECT_NE(differ.out.find("\nFAILURE\n"), std::string::npos) << differ.out;
  RunResult sizes = run("diff " + a.string() + " " + c.string());
  EXPECT_EQ(sizes.status, 2);
  EXPECT_EQ(sizes.err.rfind("error: ", 0), 0u) << sizes.err;
}

// `scenes --export` writes a built-in scene as a scene file (and its meshes as PLY beside it)
// that renders the very image of the built-in: every channel of every pixel equal (idiff's
// default threshold 1e-6, below an 8-bit step).
TEST_F(Cli, ExportedSceneRendersTheBuiltinsImage) {
  fs::path scene = dir_ / "exported" / "cornell.json";
  RunResult e = run("scenes --export cornell -o " + scene.string());
  ASSERT_EQ(e.status, 0) << e.err;
  EXPECT_TRUE(fs::exists(dir_ / "exported" / "cornell.mesh0.ply"));
  const std::string size = " --width 80 --height 60 -o ";
  fs::path from_file = dir_ / "file.png", builtin = dir_ / "builtin.png";
  ASSERT_EQ(run("render " + scene.string() + " -r raytrace" + size + from_file.string()).status, 0);
  ASSERT_EQ(run("render builtin:cornell -r raytrace" + size + builtin.string()).status, 0);
  RunResult d = run("diff " + from_file.string() + " " + builtin.string());
  EXPECT_EQ(d.status, 0) << d.out;
  EXPECT_NE(d.out.find("0 pixels (0%) over 1e-06"), std::string::npos) << d.out;
}

// --seed: builtin:dof samples the lens per pixel, so its image depends on the seed. The same seed
// gives the same bytes; seed 0 is the default; another seed moves the defocused pixels.
TEST_F(Cli, SeedChoosesTheRandomStreams) {
  auto render = [&](const std::string& name, const std::string& seed) {
    fs::path p = dir_ / (name + ".png");
    EXPECT_EQ(
        run("render builtin:dof -r raytrace --width 64 --height 48 " + seed + " -o " + p.string())
            .status,
        0);
    return p.string();
  };
  const std::string zero = render("zero", "--seed 0"), again = render("again", "--seed 0"),
                    plain = render("plain", ""), one = render("one", "--seed 1");
  EXPECT_EQ(run("diff " + zero + " " + again).status, 0);
  EXPECT_EQ(run("diff " + zero + " " + plain).status, 0);
  RunResult other = run("diff " + zero + " " + one);
  EXPECT_EQ(other.status, 1) << other.out;
  EXPECT_NE(other.out.find("\nFAILURE\n"), std::string::npos) << other.out;
}

// --triangle-test chapter runs on the binary BVH and says so; on the Cornell box (no pixel
// centre on a triangle's edge) it finds the same hits as Moller-Trumbore: the same image.
TEST_F(Cli, ChapterTriangleTestRunsOnBvh2AndRendersTheSameImage) {
  const std::string render = "render builtin:cornell -r raytrace --width 80 --height 60 ";
  fs::path chapter = dir_ / "chapter.png", mt = dir_ / "mt.png";
  RunResult c = run(render + "--triangle-test chapter --stats - -o " + chapter.string());
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(c.err.find("--triangle-test chapter runs on the binary BVH (bvh2)"), std::string::npos)
      << c.err;
  nlohmann::json stats = nlohmann::json::parse(c.out);
  EXPECT_EQ(stats["info"]["accel"], "bvh2");
  ASSERT_EQ(run(render + "--triangle-test mt -o " + mt.string()).status, 0);
  RunResult d = run("diff " + chapter.string() + " " + mt.string());
  EXPECT_EQ(d.status, 0) << d.out;
}

// The default compare (no scene, no renderers) goes through. How long it takes is a speed
// target, not a test: the process is bounded only by the suite's time limit, so a slow machine
// does not fail it.
// The demo's depth outliers are what the README calls expected: on outlines, and on the two
// analytic spheres (the z-buffer draws a polygon inside each); none elsewhere, so the report
// shows none in red.
TEST_F(Cli, DefaultCompareWritesTheReport) {
  RunResult r = run("compare -o " + (dir_ / "rvr-out").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "rvr-out" / "report.html"));
  const nlohmann::json m = nlohmann::json::parse(slurp(dir_ / "rvr-out" / "metrics.json"));
  const nlohmann::json& depth = m["depth"];
  EXPECT_EQ(depth["outliers_elsewhere"], 0) << depth.dump();
  EXPECT_GT(depth["outliers_on_analytic_spheres"].get<int>(), 0) << depth.dump();
  const std::string html = slurp(dir_ / "rvr-out" / "report.html");
  EXPECT_NE(html.find("<code>outliers_elsewhere</code></td><td class=\"num\">0<"),
            std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// Bad input, as a user meets it on the command line: every row is exit 2, exactly one line on
// stderr, starting "error: FILE:" and naming the JSON path (or the file's problem), and no file
// written. The loader's own table (test_scene_loader) checks the full messages.

namespace {

// Start-up: a run that reads or writes no image does not load OpenImageIO, whose ~260 shared
// libraries took 0.17 s and 130 MB of every run, and neither does one that writes only PNG or
// EXR (the light writer module, image_codec/src/image_writer.cpp); any other format loads it,
// through the image codec module (image_codec/). LD_DEBUG=libs makes the dynamic loader list
// every library it opens (a binary linked to OpenImageIO lists it for --version too: the
// planted case).
TEST_F(Cli, RunsWithoutImagesStartWithoutTheImageLibrary) {
  for (const char* args : {"--version", "scenes", "render builtin:nope -r raytrace -o x.png"}) {
    RunResult r = run(args, "LD_DEBUG=libs");
    EXPECT_NE(r.err.find("libc.so"), std::string::npos) << args << ": LD_DEBUG had no effect";
    EXPECT_EQ(r.err.find("libOpenImageIO"), std::string::npos) << args;
    EXPECT_EQ(r.err.find("librvr_image"), std::string::npos) << args;
  }
  for (const char* name : {"x.png", "x.exr"}) {
    const fs::path image = dir_ / name;
    RunResult r = run("render builtin:cornell -r raytrace --image 32x24 -q -o " + image.string(),
                      "LD_DEBUG=libs");
    EXPECT_EQ(r.status, 0) << name;
    EXPECT_TRUE(fs::exists(image)) << name;
    EXPECT_NE(r.err.find("librvr_image_writer.so"), std::string::npos) << name;
    EXPECT_EQ(r.err.find("libOpenImageIO"), std::string::npos) << name;
  }
  // A format only OpenImageIO writes still works, and loads it.
  const fs::path tif = dir_ / "x.tif";
  RunResult r = run("render builtin:cornell -r raytrace --image 32x24 -q -o " + tif.string(),
                    "LD_DEBUG=libs");
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(fs::exists(tif));
  EXPECT_NE(r.err.find("librvr_image_codec.so"), std::string::npos);
  EXPECT_NE(r.err.find("libOpenImageIO"), std::string::npos);
  // What the PNG run wrote is what the TIFF run wrote: 8-bit, the same bytes.
  RunResult d = run("diff " + (dir_ / "x.png").string() + " " + tif.string() + " --fail-above 0");
  EXPECT_EQ(d.status, 0) << d.out << d.err;
}

struct CliBadInput {
  const char* label;
  std::string scene;     // the scene file's text (written as bad.json), or empty
  std::string expected;  // substring of the one error line, after "error: "
};

std::string with_camera(const std::string& rest) {
  return R"({"camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]})" +
         (rest.empty() ? std::string() : ", " + rest) + "}";
}
std::string with_object(const std::string& object) {
  return with_camera(R"("objects": [)" + object + "]");
}
std::string with_sphere(const std::string& extra) {
  return with_object(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1)" + extra + "}");
}

std::vector<CliBadInput> cli_bad_inputs() {
  return {
      {"syntax", "{\"camera\": {} \"objects\": []}", "bad.json:1:15: JSON syntax"},
      {"truncated", "{\"camera\": {\"eye\": [0, 0", "bad.json:1:25: JSON syntax"},
      {"empty", "", "bad.json:1:1: JSON syntax"},
      {"binary garbage", std::string("\x89PNG\r\n\x1a\n\0\0\0", 11), "bad.json:1:1: JSON syntax"},
      {"NaN literal", with_object(R"({"type": "sphere", "center": [0, 0, 0], "radius": NaN})"),
       "bad.json:1:"},
      {"root not an object", "[1, 2, 3]", "bad.json: top level: must be an object"},
      {"unknown top-level key", with_camera(R"("objets": [])"),
       "bad.json: top level: unknown key 'objets'"},
      {"wrong format", with_camera(R"("format": "rvr-scene/9")"), "bad.json: format:"},
      {"exposure out of range", with_camera(R"("image": {"exposure": 65})"),
       "bad.json: image.exposure: must be between -64 and 64 stops"},
      {"missing camera", R"({"objects": []})", "bad.json: camera: is required"},
      {"short eye", R"({"camera": {"eye": [0, 0], "target": [0, 0, 0], "up": [0, 1, 0]}})",
       "bad.json: camera.eye:"},
      {"up parallel to view",
       R"({"camera": {"eye": [0, 5, 0], "target": [0, 0, 0], "up": [0, 1, 0]}})",
       "bad.json: camera.up:"},
      {"eye equals target",
       R"({"camera": {"eye": [0, 0, 0], "target": [0, 0, 0], "up": [0, 1, 0]}})",
       "bad.json: camera"},
      {"fov out of range",
       R"({"camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 180}})",
       "bad.json: camera.fov_y_deg:"},
      {"zero width", with_camera(R"("image": {"width": 0})"), "bad.json: image.width:"},
      {"zero samples", with_camera(R"("image": {"samples_per_pixel": 0})"),
       "bad.json: image.samples_per_pixel:"},
      {"fractional height", with_camera(R"("image": {"height": 10.5})"), "bad.json: image.height:"},
      {"negative radius", with_sphere(R"(, "radius": -1)"), "bad.json: objects[0].radius:"},
      {"duplicate key", with_sphere(R"(, "radius": 2)"),
       "bad.json: objects[0].radius: duplicate key"},
      {"radius as a string",
       with_object(R"({"type": "sphere", "center": [0, 0, 0], "radius": "1"})"),
       "bad.json: objects[0].radius:"},
      {"overflowing number",
       with_object(R"({"type": "sphere", "center": [0, 1e999, 0], "radius": 1})"),
       "bad.json: objects[0].center[1]:"},
      {"unknown object type", with_object(R"({"type": "cube"})"), "bad.json: objects[0].type:"},
      {"zero plane normal",
       with_object(R"({"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 0]})"),
       "bad.json: objects[0].normal:"},
      {"degenerate lone triangle",
       with_object(R"({"type": "triangle", "vertices": [[0, 0, 0], [1, 1, 1], [2, 2, 2]]})"),
       "bad.json: objects[0]"},
      {"undefined material", with_sphere(R"(, "material": "gold")"),
       "bad.json: objects[0].material:"},
      {"negative diffuse", with_camera(R"("materials": {"m": {"diffuse": [-0.5, 0, 0]}})"),
       "bad.json: materials.m.diffuse"},
      {"ior zero", with_camera(R"("materials": {"m": {"ior": 0}})"), "bad.json: materials.m.ior:"},
      {"negative light intensity",
       with_camera(
           R"("lights": [{"type": "point", "position": [0, 1, 0], "intensity": [-1, 1, 1]}])"),
       "bad.json: lights[0].intensity"},
      {"zero-area light",
       with_camera(
           R"("lights": [{"type": "area", "corner": [0, 1, 0], "edge_u": [1, 0, 0], "edge_v": [2, 0, 0], "intensity": [1, 1, 1]}])"),
       "bad.json: lights[0]"},
      {"missing mesh file", with_object(R"({"type": "mesh", "file": "no-such.obj"})"),
       "bad.json: objects[0].file:"},
      {"garbage mesh", with_object(R"({"type": "mesh", "file": "garbage.obj"})"),
       "bad.json: objects[0].file:"},
      {"mesh is a folder", with_object(R"({"type": "mesh", "file": "folder.obj"})"),
       "bad.json: objects[0].file:"},
      {"csg without b",
       with_object(
           R"({"type": "csg", "op": "union", "a": {"type": "sphere", "center": [0, 0, 0], "radius": 1}})"),
       "bad.json: objects[0].b:"},
      {"unknown csg op",
       with_object(
           R"({"type": "csg", "op": "xor", "a": {"type": "sphere", "center": [0, 0, 0], "radius": 1}, "b": {"type": "sphere", "center": [0, 0, 0], "radius": 1}})"),
       "bad.json: objects[0].op:"},
      {"zero scale", with_sphere(R"(, "transform": {"scale": [1, 0, 1]})"),
       "bad.json: objects[0].transform.scale"},
  };
}

}  // namespace

TEST_F(Cli, EveryBadInputIsExit2WithOneNamedErrorLineAndNoOutput) {
  auto cases = cli_bad_inputs();
  ASSERT_GE(cases.size(), 30u);
  // Inputs the mesh rows refer to.
  write("garbage.obj", std::string("\x01\x02 not a mesh \xff\xfe\n v 1 2\n f 9 9 9\n", 32));
  fs::create_directories(dir_ / "folder.obj");
  for (size_t k = 0; k < cases.size(); ++k) {
    const CliBadInput& c = cases[k];
    SCOPED_TRACE(c.label);
    write("bad.json", c.scene);
    std::vector<std::string> commands{"render " + (dir_ / "bad.json").string() +
                                      " -r raytrace -o " + (dir_ / "out.png").string() +
                                      " --aov depth --stats " + (dir_ / "stats.json").string()};
    // compare loads through the same path: every fourth row is enough (each run starts Mesa).
    if (k % 4 == 0)
      commands.push_back("compare " + (dir_ / "bad.json").string() + " -o " +
                         (dir_ / "cmp").string());
    for (const std::string& cmd : commands) {
      RunResult r = run(cmd);
      EXPECT_EQ(r.status, 2) << r.err;
      // Exactly one line, and it is the error.
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_EQ(r.err.rfind("error: " + (dir_ / "bad.json").string(), 0), 0u) << r.err;
      EXPECT_NE(r.err.find(c.expected.substr(std::string("bad.json").size())), std::string::npos)
          << "expected '" << c.expected << "' in: " << r.err;
      EXPECT_TRUE(outputs({"bad.json", "garbage.obj", "folder.obj"}).empty());
      for (const char* f : {"out.png", "out.depth.exr", "stats.json", "cmp"})
        fs::remove_all(dir_ / f);
    }
  }
}

TEST_F(Cli, MissingSceneFileAndFolderAsSceneAreExit2) {
  for (const std::string& scene : {(dir_ / "nope.json").string(), dir_.string()}) {
    RunResult r = run("render " + scene + " -r raytrace -o " + (dir_ / "x.png").string());
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("error: " + scene, 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "x.png"));
  }
}

TEST_F(Cli, OutputsGoIntoNewFoldersButNeverOverAnInput) {
  // -o into a missing folder creates it.
  RunResult ok = run("render builtin:spheres -r raytrace " + std::string(kSmall) + " -o " +
                     (dir_ / "new/sub/img.png").string());
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(fs::exists(dir_ / "new/sub/img.png"));
  // An output equal to an input is refused, and the input is untouched.
  fs::path scene = write("scene.json", with_sphere(""));
  std::string before = slurp(scene);
  RunResult same =
      run("render " + scene.string() + " -r raytrace " + kSmall + " -o " + scene.string());
  EXPECT_EQ(same.status, 2) << same.err;
  EXPECT_NE(same.err.find("error: " + scene.string()), std::string::npos) << same.err;
  EXPECT_EQ(slurp(scene), before);
  RunResult stats = run("render " + scene.string() + " -r raytrace " + kSmall + " -o " +
                        (dir_ / "a.png").string() + " --stats " + scene.string());
  EXPECT_EQ(stats.status, 2) << stats.err;
  EXPECT_EQ(slurp(scene), before);
  EXPECT_FALSE(fs::exists(dir_ / "a.png"));
  // An unwritable place is exit 2 with the path in the message.
  fs::path blocked = write("blocked", "a file, not a folder");
  RunResult unwritable = run("render " + scene.string() + " -r raytrace " + kSmall + " -o " +
                             (blocked / "img.png").string());
  EXPECT_EQ(unwritable.status, 2) << unwritable.err;
  EXPECT_NE(unwritable.err.find((blocked / "img.png").string()), std::string::npos)
      << unwritable.err;
}

namespace {

// Starts rvr with `args` (stdin, stdout and stderr on /dev/null, or stderr into `err_file`)
// and returns its pid.
pid_t spawn_rvr(const std::vector<std::string>& args, const fs::path& err_file = {}) {
  pid_t pid = ::fork();
  if (pid == 0) {
    int null = ::open("/dev/null", O_RDWR);
    if (null < 0) ::_exit(127);
    for (int fd : {0, 1, 2}) ::dup2(null, fd);
    if (!err_file.empty()) {
      int err = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (err < 0) ::_exit(127);
      ::dup2(err, 2);
    }
    std::vector<char*> argv{const_cast<char*>(RVR_BINARY)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(RVR_BINARY, argv.data());
    ::_exit(127);
  }
  return pid;
}

// Whether process `pid` has a handler for `signal_number` (the SigCgt mask of
// /proc/PID/status): rvr sets its handlers first thing in main, after the dynamic loading of
// Mesa and LLVM, which takes from half a second to seconds on a loaded machine.
bool catches(pid_t pid, int signal_number) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("SigCgt:", 0) == 0)
      return (std::stoull(line.substr(7), nullptr, 16) >> (signal_number - 1)) & 1u;
  return false;
}

// Waits (up to the process time limit) until `pid` catches `signal_number`; false if it exited
// first. Each signal's handler is installed on its own, so a test of one signal waits for that
// one (a process preempted between two installations catches SIGINT but not yet SIGTERM).
bool wait_until_catching(pid_t pid, int signal_number) {
  auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < std::chrono::seconds(RVR_PROCESS_TIMEOUT)) {
    if (catches(pid, signal_number)) return true;
    if (::waitpid(pid, nullptr, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

// Kills and reaps the child if a failed assertion leaves it running.
struct ReapOnExit {
  pid_t pid;
  ~ReapOnExit() {
    if (pid > 0 && ::waitpid(pid, nullptr, WNOHANG) == 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }
};

struct Interrupted {
  int status = -1;      // exit status, -1 when killed by a signal
  double seconds = -1;  // from SIGINT to the exit
};

Interrupted interrupt_and_wait(pid_t pid) {
  auto sent = std::chrono::steady_clock::now();
  Interrupted r;
  if (::kill(pid, SIGINT) != 0) return r;
  int raw = 0;
  if (::waitpid(pid, &raw, 0) != pid) return r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

}  // namespace

TEST_F(Cli, CtrlCWhileRenderingStopsPromptlyAndLeavesNoFile) {
  // A render of many minutes, interrupted once rvr catches the signal (so mid-render).
  pid_t pid = spawn_rvr({"render", "builtin:dof", "-r", "raytrace", "--spp", "1024", "--width",
                         "1024", "--height", "768", "-o", (dir_ / "long.png").string()});
  ASSERT_GE(pid, 0);
  ReapOnExit reap{pid};
  ASSERT_TRUE(wait_until_catching(pid, SIGINT));
  Interrupted r = interrupt_and_wait(pid);
  EXPECT_EQ(r.status, 130);
  // The handler exits at once; the bound allows for a loaded machine.
  EXPECT_LT(r.seconds, 5.0);
  EXPECT_TRUE(outputs({}).empty());
}

// docs/cli.md: SIGTERM and SIGHUP stop at once like Ctrl-C, delete the file being written and
// exit 128 + the signal number: 143 and 129.
TEST_F(Cli, SigtermAndSighupStopWithTheirExitStatusAndLeaveNoFile) {
  for (int signal_number : {SIGTERM, SIGHUP}) {
    SCOPED_TRACE(signal_number);
    pid_t pid = spawn_rvr({"render", "builtin:dof", "-r", "raytrace", "--spp", "1024", "--width",
                           "1024", "--height", "768", "-o", (dir_ / "long.png").string()});
    ASSERT_GE(pid, 0);
    ReapOnExit reap{pid};
    ASSERT_TRUE(wait_until_catching(pid, signal_number));
    ASSERT_EQ(::kill(pid, signal_number), 0);
    int raw = 0;
    ASSERT_EQ(::waitpid(pid, &raw, 0), pid);
    ASSERT_TRUE(WIFEXITED(raw)) << "killed by signal " << WTERMSIG(raw);
    EXPECT_EQ(WEXITSTATUS(raw), 128 + signal_number);
    EXPECT_TRUE(outputs({}).empty());
  }
}

// docs/cli.md: an interrupt "deletes the file being written". A camera-only scene renders
// in no time; its 2048x2048 PNG takes a while to compress. SIGINT goes the moment the temporary
// file appears (inotify), i.e. while it is being written: neither it nor the image may remain.
// The signal can land late, after the rename that finishes the image (the test process was not
// scheduled in time; under ASan the run then spends its last half second in the exit-time leak
// scan): a finished file may stay, but only whole, the same bytes as an uninterrupted run's.
// So: no temporary ever, no partial image ever, and at least one of five tries interrupted
// during the write with nothing left.
TEST_F(Cli, CtrlCWhileWritingDeletesThePartialFile) {
  fs::path scene =
      write("camera_only.json", with_camera(R"("image": {"width": 2048, "height": 2048})"));
  const std::vector<std::string> render = {"render", scene.string(), "-r", "raytrace",
                                           "--mode", "local",        "-o"};
  RunResult whole_run = run("render " + scene.string() + " -r raytrace --mode local -o " +
                            (dir_ / "whole.png").string());
  ASSERT_EQ(whole_run.status, 0) << whole_run.err;
  const std::string whole = slurp(dir_ / "whole.png");
  int interrupted_mid_write = 0;
  for (int attempt = 0; attempt < 5 && interrupted_mid_write == 0; ++attempt) {
    SCOPED_TRACE("attempt " + std::to_string(attempt));
    fs::path out_dir = dir_ / ("out" + std::to_string(attempt));
    fs::create_directories(out_dir);
    int watch = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    ASSERT_GE(watch, 0);
    ASSERT_GE(::inotify_add_watch(watch, out_dir.c_str(), IN_CREATE), 0);
    std::vector<std::string> args = render;
    args.push_back((out_dir / "big.png").string());
    pid_t pid = spawn_rvr(args);
    ASSERT_GE(pid, 0);
    ReapOnExit reap{pid};
    std::string created;
    alignas(inotify_event) char buf[4096];
    auto start = std::chrono::steady_clock::now();
    while (created.empty() &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(RVR_PROCESS_TIMEOUT)) {
      pollfd p{watch, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      ssize_t n = ::read(watch, buf, sizeof buf);
      for (ssize_t at = 0; at < n;) {
        const auto* e = reinterpret_cast<const inotify_event*>(buf + at);
        if (e->len) created = e->name;
        at += ssize_t(sizeof(inotify_event) + e->len);
      }
    }
    ::close(watch);
    ASSERT_FALSE(created.empty()) << "no file was created";
    Interrupted r = interrupt_and_wait(pid);
    // The first file made is the temporary one ("DIR/.big.tmp-<pid>-<n>.png"), never the image.
    EXPECT_EQ(created.rfind(".big.tmp-", 0), 0u) << created;
    // 130: interrupted; 0: the run had ended before the signal came.
    EXPECT_TRUE(r.status == 130 || r.status == 0) << r.status;
    std::vector<fs::path> left;
    for (const fs::directory_entry& e : fs::directory_iterator(out_dir)) left.push_back(e.path());
    for (const fs::path& p : left) {
      EXPECT_EQ(p.filename(), "big.png") << "left behind: " << p;
      if (p.filename() == "big.png") {
        EXPECT_TRUE(slurp(p) == whole) << "a partial image: " << p;
      }
    }
    if (r.status == 130 && left.empty()) ++interrupted_mid_write;
  }
  EXPECT_EQ(interrupted_mid_write, 1) << "no try was interrupted during the write";
}

TEST_F(Cli, LimitsRefuseHugeWorkBeforeAnyAllocationAndFlagsRaiseThem) {
  struct Row {
    std::string args, expected;
  };
  const Row rows[] = {
      {"builtin:cornell --width 16384 --height 16384 --spp 64",
       "error: builtin:cornell: image: 16384x16384 pixels x 64 samples = 17179869184 samples, "
       "over the limit of 1073741824 (raise it with --max-samples)"},
      {"builtin:tessphere:100000 --max-triangles 1000",
       "error: builtin:tessphere:100000: objects: 99538 triangles"},
      {"builtin:cornell --width 4096 --height 4096 --max-memory-mb 100",
       "error: builtin:cornell: image, objects: about"},
  };
  for (const Row& row : rows) {
    auto start = std::chrono::steady_clock::now();
    RunResult r = run("render " + row.args + " -r raytrace -o " + (dir_ / "x.png").string());
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind(row.expected, 0), 0u) << r.err;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              10.0);
    EXPECT_TRUE(outputs({}).empty());
  }
  // Raised, the same small render goes through.
  RunResult ok = run("render builtin:tessphere:100000 -r raytrace --max-triangles 200000 " +
                     std::string(kSmall) + " -o " + (dir_ / "x.png").string());
  EXPECT_EQ(ok.status, 0) << ok.err;
}

TEST_F(Cli, EndlessOrHugeSceneFileIsRefused) {
  auto start = std::chrono::steady_clock::now();
  RunResult r = run("render /dev/zero -r raytrace -o " + (dir_ / "x.png").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err,
            "error: /dev/zero: the scene file is over 256 MiB (meshes belong in mesh files)\n");
  // No hang: it stops after 256 MiB (seconds natively, longer under AddressSanitizer).
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 90.0);
  EXPECT_TRUE(outputs({}).empty());
}

TEST_F(Cli, InfoHasWhatABugReportNeeds) {
  RunResult r = run("info");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* field :
       {"rvr ", "cpu: ", "hardware threads", "renderers: raster softraster",
        "simd: baseline build ", "kernels: ", "compiled: sse avx2 avx512", "this CPU runs: sse",
        "embree: 3.", "openimageio: ", "tbb: ", "gl backend: osmesa",
        "GL_VERSION: ", "GL_RENDERER: llvmpipe", "llvmpipe threads: "})
    EXPECT_NE(r.out.find(field), std::string::npos) << field << " missing in:\n" << r.out;
}

// RVR_ISA forces the tracer's SIMD kernels: the image is the same bytes whichever runs; a bad
// value or one this CPU cannot run is refused before any work, one line, exit 2.
TEST_F(Cli, RvrIsaForcesTheKernelsAndImagesDoNotChange) {
  RunResult info = run("info", "RVR_ISA=sse");
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("kernels: sse (forced by RVR_ISA)"), std::string::npos) << info.out;

  const std::string args = "render builtin:cornell -r raytrace --mode full --width 96 --height 72 ";
  std::vector<std::string> isas{"sse"};
  RunResult avx2 = run("info", "RVR_ISA=avx2");
  if (avx2.out.find("this CPU runs: sse avx2") != std::string::npos) isas.push_back("avx2");
  if (avx2.out.find("this CPU runs: sse avx2 avx512") != std::string::npos)
    isas.push_back("avx512");
  std::string first;
  for (const std::string& isa : isas) {
    fs::path png = dir_ / (isa + ".png"), stats = dir_ / (isa + ".json");
    RunResult r = run(args + "-o " + png.string() + " --stats " + stats.string(), "RVR_ISA=" + isa);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(slurp(stats).find("\"kernel\": \"" + isa + "\""), std::string::npos) << slurp(stats);
    if (first.empty()) first = slurp(png);
    EXPECT_EQ(slurp(png), first) << isa << " gives other bytes than " << isas[0];
  }

  for (const char* bad : {"RVR_ISA=avx3", "RVR_ISA=AVX2"}) {
    RunResult r = run(args + "-o " + (dir_ / "bad.png").string(), bad);
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_EQ(r.err, std::string("error: ") + bad + ": unknown (use sse, avx2 or avx512)\n");
    EXPECT_FALSE(fs::exists(dir_ / "bad.png"));
  }
  if (isas.size() < 3) {  // a CPU without AVX-512 is told so, for render and compare alike
    RunResult r = run(args + "-o " + (dir_ / "bad.png").string(), "RVR_ISA=avx512");
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.err.rfind("error: RVR_ISA=avx512: this CPU cannot run avx512 kernels", 0), 0u)
        << r.err;
    RunResult c =
        run("compare builtin:cornell --width 32 --height 24 -o " + (dir_ / "cmp").string(),
            "RVR_ISA=avx512");
    EXPECT_EQ(c.status, 2);
    EXPECT_EQ(std::count(c.err.begin(), c.err.end(), '\n'), 1) << c.err;
    EXPECT_FALSE(fs::exists(dir_ / "cmp"));
  }
}

// --accel: the wide BVH (default), the binary one, or none; the same image from all three.
TEST_F(Cli, AccelChoicesRenderTheSameImage) {
  const std::string args = "render builtin:spheres -r raytrace --width 64 --height 48 ";
  std::string first;
  for (const char* accel : {"bvh", "bvh2", "none"}) {
    fs::path png = dir_ / (std::string(accel) + ".png"),
             stats = dir_ / (std::string(accel) + ".json");
    RunResult r =
        run(args + "--accel " + accel + " -o " + png.string() + " --stats " + stats.string());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(slurp(stats).find(std::string("\"accel\": \"") + accel + "\""), std::string::npos);
    if (first.empty()) first = slurp(png);
    EXPECT_EQ(slurp(png), first) << accel;
  }
  RunResult bad = run(args + "--accel bvh4 -o " + (dir_ / "x.png").string());
  EXPECT_EQ(bad.status, 2);
}

// --gl picks the raster's GL back end; by default OSMesa, falling back to EGL (and saying so)
// when libOSMesa cannot be loaded, which RVR_OSMESA_LIBRARY simulates.
TEST_F(Cli, GlBackendsAndTheFallbackToEgl) {
  RunResult egl = run("info --gl egl");
  ASSERT_EQ(egl.status, 0) << egl.err;
  EXPECT_NE(egl.out.find("gl backend: egl\n"), std::string::npos) << egl.out;
  EXPECT_NE(egl.out.find("GL_RENDERER: llvmpipe"), std::string::npos) << egl.out;

  const std::string args = "render builtin:cornell -r raster --width 64 --height 48 -o ";
  RunResult a = run(args + (dir_ / "osmesa.png").string() + " --gl osmesa");
  ASSERT_EQ(a.status, 0) << a.err;
  RunResult b = run(args + (dir_ / "egl.png").string() + " --gl egl");
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_EQ(slurp(dir_ / "osmesa.png"), slurp(dir_ / "egl.png"));

  const std::string missing = "RVR_OSMESA_LIBRARY=/nonexistent/libOSMesa.so.8";
  RunResult fallback = run(args + (dir_ / "fallback.png").string(), missing);
  ASSERT_EQ(fallback.status, 0) << fallback.err;
  EXPECT_NE(fallback.err.find("warning: raster: OSMesa unavailable (cannot load "
                              "/nonexistent/libOSMesa.so.8"),
            std::string::npos)
      << fallback.err;
  EXPECT_NE(fallback.err.find("using EGL surfaceless instead"), std::string::npos);
  EXPECT_EQ(slurp(dir_ / "osmesa.png"), slurp(dir_ / "fallback.png"));

  // Asked for by name, OSMesa does not fall back: an internal failure (exit 3), one line.
  RunResult refused = run(args + (dir_ / "refused.png").string() + " --gl osmesa", missing);
  EXPECT_EQ(refused.status, 3);
  EXPECT_EQ(refused.err.rfind("error: ", 0), 0u) << refused.err;
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_FALSE(fs::exists(dir_ / "refused.png"));
}

// docs/cli.md, "rvr study": the first Ctrl-C stops the sweep, and the study of the points
// measured so far is written, valid and marked interrupted; exit 130 with one line on stderr.
TEST_F(Cli, CtrlCDuringAStudyWritesThePartialStudy) {
  fs::path out = dir_ / "study", err = dir_ / "stderr.txt";
  pid_t pid = spawn_rvr({"study", "builtin:tessphere", "builtin:soup", "--width", "128", "--budget",
                         "600", "-q", "-o", out.string()},
                        err);
  ASSERT_GE(pid, 0);
  ReapOnExit reap{pid};
  ASSERT_TRUE(wait_until_catching(pid, SIGINT));
  std::this_thread::sleep_for(std::chrono::seconds(3));  // the first points take milliseconds
  Interrupted r = interrupt_and_wait(pid);
  std::string message = slurp(err);
  EXPECT_EQ(r.status, 130) << message;
  EXPECT_EQ(message.rfind("rvr study: interrupted; wrote " + out.string() +
                              "/{study.json,study.md,study.html} from ",
                          0),
            0u)
      << message;
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
  ASSERT_TRUE(fs::exists(out / "study.md"));
  nlohmann::json study = nlohmann::json::parse(slurp(out / "study.json"));
  EXPECT_EQ(study["interrupted"], true);
  EXPECT_GE(study["points"].size(), 1u);
  EXPECT_LT(r.seconds, 30.0) << "the sweep went on after the interrupt";
}

// --merge of two studies of this machine (one of them shard 1/2) pools them (a point both
// measured keeps the runs of each, each run a session of its own); with the SIMD kernels of one
// edited, they are not pooled: one study per machine type and comparison.md.
TEST_F(Cli, StudyMergePoolsOneMachineTypeAndComparesTwo) {
  // A 3 s study may measure too few points to conclude on a slow machine (ASan, a loaded CI
  // runner): then it exits 1 saying why, with its study.json written, which is all a merge
  // needs; any other failure fails the test.
  auto written = [](const RunResult& r) {
    return r.status == 0 ||
           (r.status == 1 && r.err.find("rvr study: no conclusion: ") != std::string::npos);
  };
  const std::string tiny = "study builtin:tessphere --width 32 --budget 3 -q -o ";
  for (const char* name : {"a", "b"}) {
    RunResult r = run(tiny + (dir_ / name).string() + (name[0] == 'b' ? " --shard 1/2" : ""));
    ASSERT_TRUE(written(r)) << r.status << ": " << r.err;
  }
  nlohmann::json a = nlohmann::json::parse(slurp(dir_ / "a" / "study.json"));
  nlohmann::json b = nlohmann::json::parse(slurp(dir_ / "b" / "study.json"));
  EXPECT_TRUE(a["shard"].is_null());
  EXPECT_EQ(b["shard"], (nlohmann::json{{"index", 1}, {"count", 2}}));

  fs::path pooled = dir_ / "pooled";
  RunResult merged = run("study --merge " + (dir_ / "a").string() + " " + (dir_ / "b").string() +
                         " -o " + pooled.string());
  ASSERT_TRUE(written(merged)) << merged.status << ": " << merged.err;
  nlohmann::json p = nlohmann::json::parse(slurp(pooled / "study.json"));
  EXPECT_TRUE(fs::exists(pooled / "study.md"));
  // A point both measured keeps every run of each, and the sessions of both studies.
  std::map<std::string, size_t> runs_of;  // by point
  for (const nlohmann::json* doc : {&a, &b})
    for (const nlohmann::json& point : (*doc)["points"]) {
      std::string key = point["renderer"].dump() + point["scene_n"].dump() + point["width"].dump();
      runs_of[key] += point["runs"].size();
    }
  for (const nlohmann::json& point : p["points"]) {
    std::string key = point["renderer"].dump() + point["scene_n"].dump() + point["width"].dump();
    EXPECT_EQ(point["runs"].size(), runs_of[key]) << key;
  }
  EXPECT_EQ(p["sessions"].size(), a["sessions"].size() + b["sessions"].size());
  EXPECT_EQ(p["merged_runs"].size(), 2u);
  EXPECT_LE(p["points"].size(), a["points"].size() + b["points"].size());
  EXPECT_GE(p["points"].size(), std::max(a["points"].size(), b["points"].size()));
  EXPECT_EQ(p["budget_seconds"], 6.0);

  b["machine"]["kernels"] = "sse (edited: another machine type)";
  fs::create_directories(dir_ / "b_sse");
  std::ofstream(dir_ / "b_sse" / "study.json") << b.dump(2);
  fs::path compared = dir_ / "compared";
  RunResult apart = run("study --merge " + (dir_ / "a").string() + " " + (dir_ / "b_sse").string() +
                        " -o " + compared.string());
  ASSERT_TRUE(written(apart)) << apart.status << ": " << apart.err;
  ASSERT_TRUE(fs::exists(compared / "comparison.md"));
  EXPECT_NE(slurp(compared / "comparison.md").find("sse (edited"), std::string::npos);
  int studies = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(compared))
    if (e.is_directory()) studies += fs::exists(e.path() / "study.json");
  EXPECT_EQ(studies, 2);
}

TEST_F(Cli, StudyShardAndMergeRefuseBadInput) {
  struct Case {
    std::string args, words;
  };
  const std::string out = " -o " + (dir_ / "out").string();
  for (const Case& c : std::vector<Case>{
           {"study --shard 8/8" + out, "error: --shard: "},
           {"study --shard 1" + out, "error: --shard: "},
           {"study --merge " + (dir_ / "none").string() + out, "/none/study.json: "},
           {"study --merge " + dir_.string() + " --shard 0/2" + out, "--shard"},
           {"study --merge " + write("study.json", "{}").parent_path().string() + out,
            "study.json: format: is required"},
       }) {
    RunResult r = run(c.args);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << c.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out")) << c.args;
  }
}

// Issue 26, item 6: the messages a user reads.

// A renderer's warning is printed "warning: RENDERER: what", the renderer named once, and
// reaches metrics.json and report.html with the same text.
TEST_F(Cli, WarningsNameTheirRendererOnce) {
  const std::string note =
      "refraction on 2 transparent objects (slab, glass ball) from cube maps drawn at each "
      "object's centre: no parallax (the map is seen from the centre, not the surface point), no "
      "self-reflection, refraction at the first interface only (slab), a sphere's back surface "
      "shaded as its front, and one bounce (what a map shows keeps its own mirrors' and glass's "
      "local colour)";
  RunResult r = run("render builtin:glass -r softraster --mode full --spp 2 " +
                    std::string(kSmall) + " -o " + (dir_ / "g.png").string() + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: softraster: " + note + "\n"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("softraster: softraster"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("by softraster"), std::string::npos) << r.err;

  // The hybrid's tracer refracts: its z-buffer's full-mode note is not its own.
  RunResult hybrid = run("render builtin:glass -r hybrid_soft --mode full --spp 2 " +
                         std::string(kSmall) + " -o " + (dir_ / "h.png").string() + " --quiet");
  ASSERT_EQ(hybrid.status, 0) << hybrid.err;
  EXPECT_EQ(hybrid.err.find(note), std::string::npos) << hybrid.err;

  fs::path out = dir_ / "cmp";
  RunResult c = run("compare builtin:glass -r softraster,raytrace --mode full " +
                    std::string(kSmall) + " -o " + out.string() + " --quiet");
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(c.err.find("warning: softraster: " + note + "\n"), std::string::npos) << c.err;
  EXPECT_EQ(c.err.find("softraster: softraster"), std::string::npos) << c.err;
  nlohmann::json metrics = nlohmann::json::parse(slurp(out / "metrics.json"));
  const auto soft_warnings =
      metrics["renderers"]["softraster"]["warnings"].get<std::vector<std::string>>();
  EXPECT_EQ(soft_warnings, std::vector<std::string>{note});
  std::string escaped;  // the report writes an apostrophe as &#39;
  for (char ch : note) escaped += ch == '\'' ? std::string("&#39;") : std::string(1, ch);
  EXPECT_NE(slurp(out / "report.html").find("<b>softraster</b>: " + escaped), std::string::npos);
}

// Outputs are written to a temporary beside them and renamed into place; an error names the
// path the user gave, never the temporary.
TEST_F(Cli, OutputErrorNamesTheUsersPathNotTheTemporary) {
  const std::string out = (dir_ / "t.xyz").string();
  RunResult r = run("render builtin:spheres -r raytrace --mode local " + std::string(kSmall) +
                    " -o " + out + " --quiet");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: cannot write '" + out + "': ", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find(".tmp-"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(outputs({}).empty());
}

// --export of a file that is not there says so; a bare word is still a built-in scene.
TEST_F(Cli, ExportOfAMissingFileSaysTheFileIsMissing) {
  RunResult r = run("scenes --export missing.obj");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "error: missing.obj: no such file\n");
  const std::string in_folder = (dir_ / "models" / "engine.glb").string();
  r = run("scenes --export " + in_folder);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "error: " + in_folder + ": no such file\n");
  r = run("scenes --export nope");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "error: builtin:nope: no such built-in scene (see 'rvr scenes')\n");
  r = run("scenes --export tessphere:2.5");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("error: builtin:tessphere:2.5: N must be an integer in 1..", 0), 0u)
      << r.err;
  EXPECT_EQ(run("scenes --export spheres").status, 0);  // a bare name: the built-in scene
  EXPECT_TRUE(outputs({}).empty());
}

// Every option of the render option table refuses, in one error line and exit 2, a value just
// outside its range or not in its list, with the table's message after the option's name.
TEST_F(Cli, RenderOptionsRefuseWhatTheTableRefuses) {
  for (const rvr::RenderOptionSpec& spec : rvr::render_option_table()) {
    const std::string name = rvr::cli_option_name(spec);
    std::vector<std::pair<std::string, std::string>> cases;  // value, message after "name: "
    auto text = [](double v) {
      std::ostringstream s;
      s << v;
      return s.str();
    };
    const std::string range = "must be " + text(spec.min) + " to " + text(spec.max) + ", got ";
    if (spec.type == rvr::OptionType::Integer || spec.type == rvr::OptionType::Real) {
      cases.emplace_back(text(spec.min - 1), range + text(spec.min - 1));
      cases.emplace_back(text(spec.max + 1), range + text(spec.max + 1));
    }
    if (spec.type == rvr::OptionType::Choice) {
      std::string known;
      for (std::string_view c : spec.choices) known += (known.empty() ? "" : ", ") + std::string(c);
      cases.emplace_back("zzzz", "'zzzz' is not one of " + known);
    }
    for (const auto& [value, message] : cases) {
      RunResult r =
          run("render -r raytrace -q " + name + " " + value + " -o " + (dir_ / "out.png").string());
      EXPECT_EQ(r.status, 2) << name << " " << value;
      EXPECT_EQ(r.err, "error: " + name + ": " + message + "\n");
    }
  }
  EXPECT_TRUE(outputs({}).empty());
}

// An option the renderer does not read (the render option table's readers) is a warning of that
// renderer's, where its other warnings go: stderr once, render --stats, metrics.json under the
// renderer and the report. An option it reads is not.
TEST_F(Cli, OptionsTheRendererDoesNotReadAreWarnings) {
  const fs::path stats = dir_ / "stats.json";
  RunResult render = run("render builtin:cornell -r raytrace " + std::string(kSmall) +
                         " --shadow-map-size 512 --accel bvh2 -o " + (dir_ / "r.png").string() +
                         " --stats " + stats.string());
  ASSERT_EQ(render.status, 0) << render.err;
  const std::string unread = "option --shadow-map-size is not read by raytrace";
  EXPECT_EQ(render.err.find("warning: raytrace: " + unread + "\n"),
            render.err.rfind("warning: raytrace: " + unread + "\n"));
  EXPECT_NE(render.err.find("warning: raytrace: " + unread + "\n"), std::string::npos)
      << render.err;
  EXPECT_EQ(render.err.find("--accel"), std::string::npos) << render.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(stats))["warnings"], nlohmann::json::array({unread}));

  const fs::path out = dir_ / "cmp";
  RunResult cmp = run("compare builtin:cornell -r softraster,raytrace " + std::string(kSmall) +
                      " --accel none --hiz off -q -o " + out.string());
  ASSERT_EQ(cmp.status, 0) << cmp.err;
  const nlohmann::json m = nlohmann::json::parse(slurp(out / "metrics.json"));
  EXPECT_EQ(m["renderers"]["softraster"]["warnings"],
            nlohmann::json::array({"option --accel is not read by softraster"}));
  EXPECT_EQ(m["renderers"]["raytrace"]["warnings"],
            nlohmann::json::array({"option --hiz is not read by raytrace"}));
  EXPECT_NE(cmp.err.find("warning: softraster: option --accel is not read by softraster\n"),
            std::string::npos)
      << cmp.err;
  const std::string html = slurp(out / "report.html");
  EXPECT_NE(html.find("<li><b>raytrace</b>: option --hiz is not read by raytrace</li>"),
            std::string::npos);
}

// An unknown command or option names the nearest known one, in one error line, exit 2.
TEST_F(Cli, UnknownCommandOrOptionSuggestsTheNearest) {
  const std::map<std::string, std::string> expected = {
      {"rendr", "error: unknown command 'rendr': did you mean 'render'?\n"},
      {"compare --renderer x",
       "error: compare: unknown option '--renderer': did you mean '--renderers'?\n"},
      {"compare --renderer=raster,raytrace",
       "error: compare: unknown option '--renderer': did you mean '--renderers'?\n"},
      // The typo leaves -r missing too: the typo is what is reported.
      {"render --rendrer raytrace",
       "error: render: unknown option '--rendrer': did you mean '--renderer'?\n"},
      {"diff a.png b.png --failpercnt 5",
       "error: diff: unknown option '--failpercnt': did you mean '--failpercent'?\n"},
      {"frobnicate",
       "error: unknown command 'frobnicate' (commands: render, compare, diff, scenes, info, "
       "study)\n"},
      {"render -r raytrace --zzzzzz",
       "error: render: unknown option '--zzzzzz' (see 'rvr render --help')\n"},
      {"info extra", "error: info: unexpected argument 'extra'\n"},
      // A value out of a list: the list, and the nearest name.
      {"render -r raytrace --texture-lod cone",
       "error: --texture-lod: 'cone' is not one of cones, differentials, none: did you mean "
       "'cones'?\n"},
      {"render -r raytrace --texture-lod zzzz",
       "error: --texture-lod: 'zzzz' is not one of cones, differentials, none\n"},
      {"render -r raytrace --mode ful",
       "error: --mode: 'ful' is not one of visibility, local, full: did you mean 'full'?\n"},
      {"render -r raytrace --camera fil",
       "error: --camera: 'fil' is not one of file, auto, file-always: did you mean 'file'?\n"},
      {"render -r softrastr",
       "error: --renderer: 'softrastr' is not one of raster, softraster, raytrace, embree, "
       "hybrid, hybrid_soft: did you mean 'softraster'?\n"},
      {"compare -r raster,raytrce",
       "error: --renderers: 'raytrce' is not one of raster, softraster, raytrace, embree, "
       "hybrid, hybrid_soft: did you mean 'raytrace'?\n"},
  };
  for (const auto& [args, message] : expected) {
    RunResult r = run(args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_EQ(r.err, message) << args;
  }
  EXPECT_TRUE(outputs({}).empty());
}

namespace {

// An output file that names a folder, existing or ending in '/', is refused before any work
// with "is a directory" (not the image library's "could not find a format writer"), and no
// folder is made for it.
TEST_F(Cli, OutputFileThatIsAFolderIsRefused) {
  fs::create_directories(dir_ / "folder");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"render builtin:spheres -r softraster -q -o ", (dir_ / "folder").string()},
      {"render builtin:spheres -r softraster -q -o ", (dir_ / "made" / "").string()},
      {"render builtin:spheres -r softraster -q --stats ", (dir_ / "folder").string()},
      {"scenes --export spheres -o ", (dir_ / "made" / "").string()},
  };
  for (const auto& [args, out] : cases) {
    RunResult r = run(args + out);
    EXPECT_EQ(r.status, 2) << args << out;
    EXPECT_EQ(r.err, "error: cannot write '" + out + "': is a directory\n") << args << out;
  }
  EXPECT_FALSE(fs::exists(dir_ / "made"));
  EXPECT_TRUE(fs::is_empty(dir_ / "folder"));
}

// A .gltf whose JSON does not parse says where, as a scene file's JSON errors do: the line and
// column (counted here from the text written) and, for a file cut short, that the file ends
// there.
TEST_F(Cli, GltfWithBrokenJsonSaysWhere) {
  const std::string json = rvr::test::corpus::gltf_json(rvr::test::corpus::GltfExtras{}, false);
  ASSERT_EQ(json.find('\n'), std::string::npos);  // one line: the column is the offset + 1
  const size_t colon = json.find(':');
  const fs::path cut = write("cut.gltf", json.substr(0, colon + 1));
  RunResult r = run("render " + cut.string() + " -r softraster -q");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "error: " + cut.string() + ": cannot read '" + cut.string() +
                       "': JSON syntax at line 1, column " + std::to_string(colon + 2) +
                       ", where the file ends: unexpected end of input (expected a value)\n");
  // A comma missing before "nodes": the string after the bracket is reported where it starts.
  std::string broken = json;
  const size_t nodes = broken.find("],\"nodes\"");
  ASSERT_NE(nodes, std::string::npos);
  broken.erase(nodes + 1, 1);
  const fs::path bad = write("bad.gltf", "{\n" + broken.substr(1));
  r = run("render " + bad.string() + " -r softraster -q");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "error: " + bad.string() + ": cannot read '" + bad.string() +
                       "': JSON syntax at line 2, column " + std::to_string(nodes + 1) +
                       ": expected ',' or '}', got a string\n");
  EXPECT_TRUE(outputs({"cut.gltf", "bad.gltf"}).empty());
}

// A path in an error message is printed whole, however long.
TEST_F(Cli, LongPathsInErrorsArePrintedWhole) {
  const fs::path folder = dir_ / std::string(150, 'd') / std::string(150, 'e');
  fs::create_directories(folder);
  const std::string mesh = (folder / (std::string(100, 'm') + ".obj")).string();
  const fs::path scene =
      write("long.json", R"({"camera": {"eye": [0, 0, 4], "target": [0, 0, 0], "up": [0, 1, 0]},
    "objects": [{"type": "mesh", "file": ")" +
                             mesh + R"("}]})");
  RunResult r = run("render " + scene.string() + " -r softraster -q");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "error: " + scene.string() + ": objects[0].file: cannot read '" + mesh +
                       "': No such file or directory\n");
}

}  // namespace
