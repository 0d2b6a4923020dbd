// The rvr command line, run as a user runs it: exit codes 0/1/2/3, outputs, and nothing
// written when the input is bad.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

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
    dir_ = fs::temp_directory_path() /
           ("rvr_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
            "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  RunResult run(const std::string& args, const std::string& env = "") {
    fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    std::string cmd = env + " " + std::string(RVR_BINARY) + " " + args + " >" + out.string() +
                      " 2>" + err.string() + " </dev/null";
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
  RunResult r = run("render builtin:cornell -r raytrace " + std::string(kSmall) + " -o " +
                    out.string() + " --aov depth,id,normal,cost --stats " +
                    (dir_ / "stats.json").string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"img.png", "img.depth.exr", "img.id.exr", "img.normal.exr",
                        "img.cost.exr", "img.cost.png"})
    EXPECT_TRUE(fs::exists(dir_ / "sub" / f)) << f;
  nlohmann::json stats = nlohmann::json::parse(slurp(dir_ / "stats.json"));
  EXPECT_EQ(stats["renderer"], "raytrace");
  EXPECT_GT(stats["stats"]["rays.primary"].get<double>(), 80 * 60 - 1);
  EXPECT_TRUE(stats["time"].contains("render"));
  EXPECT_TRUE(stats["time"].contains("load"));
  EXPECT_TRUE(stats["time"].contains("write"));
  EXPECT_GT(stats["peak_memory_bytes"].get<double>(), 0.0);
}

TEST_F(Cli, RasterRenders) {
  RunResult r = run("render builtin:spheres -r raster --mode local " + std::string(kSmall) +
                    " -o " + (dir_ / "r.exr").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "r.exr"));
}

TEST_F(Cli, BadSceneIsExit2WithOneErrorLineAndNoOutput) {
  fs::path scene = write("bad.json", R"({"camera": {"eye": [0,0,5], "target": [0,0,0], "up": [0,1,0]},
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
  fs::path scene = write("syntax.json", "{\n  \"camera\": {\n    \"eye\": [0, 0, 5]\n    \"target\": [0,0,0]\n}\n");
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

TEST_F(Cli, SoftpipeIsRefusedWithExit3) {
  RunResult r = run("render builtin:cornell -r raster " + std::string(kSmall) + " -o " +
                        (dir_ / "x.png").string(),
                    "GALLIUM_DRIVER=softpipe");
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("softpipe"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));
}

TEST_F(Cli, CompareWritesEverythingAndThresholdGivesExit1) {
  fs::path out = dir_ / "cmp";
  RunResult r = run("compare builtin:soup:3000 --width 160 --height 120 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"raster.png", "raytrace.png", "diff.png", "id_mismatch.png",
                        "metrics.json", "report.html"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  nlohmann::json m = nlohmann::json::parse(slurp(out / "metrics.json"));
  for (const char* key : {"scene", "width", "height", "mode", "renderers", "visibility", "depth", "color"})
    EXPECT_TRUE(m.contains(key)) << key;
  double agreement = m["visibility"]["id_agreement"].get<double>();
  EXPECT_GT(agreement, 0.99);
  EXPECT_NE(r.out.find("id agreement"), std::string::npos);
  // A threshold above what was measured is crossed: exit 1.
  if (agreement < 1.0) {
    EXPECT_EQ(run("compare builtin:soup:3000 --width 160 --height 120 --fail-below-agreement 1 -o " +
                  out.string())
                  .status,
              1);
  }
}

TEST_F(Cli, DiffReportsAndFailsAboveThreshold) {
  fs::path a = dir_ / "a.png", b = dir_ / "b.png", c = dir_ / "c.png";
  ASSERT_EQ(run("render builtin:cornell -r raytrace --mode local " + std::string(kSmall) + " -o " + a.string()).status, 0);
  ASSERT_EQ(run("render builtin:spheres -r raytrace --mode local " + std::string(kSmall) + " -o " + b.string()).status, 0);
  ASSERT_EQ(run("render builtin:cornell -r raytrace --mode local --width 40 --height 30 -o " + c.string()).status, 0);
  RunResult same = run("diff " + a.string() + " " + a.string());
  EXPECT_EQ(same.status, 0) << same.err;
  RunResult differ = run("diff " + a.string() + " " + b.string() + " --fail-above 0.001 -o " +
                         (dir_ / "heat.png").string());
  EXPECT_EQ(differ.status, 1) << differ.err;
  EXPECT_NE(differ.out.find("RMS"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "heat.png"));
  RunResult sizes = run("diff " + a.string() + " " + c.string());
  EXPECT_EQ(sizes.status, 2);
  EXPECT_EQ(sizes.err.rfind("error: ", 0), 0u) << sizes.err;
}

TEST_F(Cli, DefaultCompareFinishesInUnderAMinute) {
  auto start = std::chrono::steady_clock::now();
  RunResult r = run("compare -o " + (dir_ / "rvr-out").string());
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(seconds, 60.0);
  EXPECT_TRUE(fs::exists(dir_ / "rvr-out" / "report.html"));
}
