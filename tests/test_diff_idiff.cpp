// `rvr diff` against OpenImageIO's idiff (/usr/bin/idiff, openimageio-tools): on pairs of EXR and
// PNG images made here, both programs must give the same verdict (PASS / WARNING / FAILURE), the
// same "N pixels (P%) over T" lines and the same worst pixel. rvr's exit status is 0 for PASS,
// 1 for WARNING or FAILURE, 2 for images that cannot be compared (idiff's: 0, 1, 2 and 3-4).
// idiff runs with -v so that it prints its counts for a PASS too. When idiff is missing the test
// fails rather than skips.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/image_codec/image_io.h"

namespace fs = std::filesystem;

namespace {

constexpr const char* kIdiff = "/usr/bin/idiff";

struct Outcome {
  int status = -1;
  std::string out;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// What a report says, in the words both programs use.
struct Report {
  std::string verdict;                  // last line: PASS, WARNING or FAILURE
  std::vector<std::string> over_lines;  // "N pixels (P%) over T", warn line then fail line
  std::string max_line;                 // "Max error  = ..."
};

Report parse(const std::string& out) {
  Report r;
  std::istringstream in(out);
  std::string line;
  static const std::regex over(R"(^\s+(\d+ pixels \([^)]*%\) over \S+)$)");
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, over)) r.over_lines.push_back(m[1]);
    if (line.find("Max error") != std::string::npos) r.max_line = line;
    if (line == "PASS" || line == "WARNING" || line == "FAILURE") r.verdict = line;
  }
  return r;
}

class DiffVsIdiff : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rvr_diff_idiff_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Outcome run(const std::string& command) {
    const fs::path out = dir_ / "stdout.txt";
    const std::string cmd = "timeout -k 10 " + std::to_string(RVR_PROCESS_TIMEOUT) + " " + command +
                            " >" + out.string() + " 2>/dev/null </dev/null";
    const int raw = std::system(cmd.c_str());
    Outcome r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    return r;
  }

  fs::path save(const std::string& name, const rvr::Image& image) {
    const fs::path p = dir_ / name;
    // As they are: PNG stores round(255 v), EXR the floats.
    EXPECT_TRUE(rvr::write_image(p.string(), image, false).ok()) << p;
    return p;
  }

  // One pair, one set of options ("--fail 0.1 ..." for rvr; idiff spells them with one dash).
  void same_verdict(const fs::path& a, const fs::path& b, const std::string& options,
                    const std::string& expected_verdict, const std::string& what) {
    SCOPED_TRACE(what + " [" + options + "] " + a.filename().string());
    ASSERT_TRUE(fs::exists(kIdiff)) << "idiff is missing (apt-get install openimageio-tools)";
    const std::string idiff_options = std::regex_replace(options, std::regex("--"), "-");
    const Outcome theirs =
        run(std::string(kIdiff) + " -v " + idiff_options + " " + a.string() + " " + b.string());
    const Outcome ours =
        run(std::string(RVR_BINARY) + " diff " + a.string() + " " + b.string() + " " + options);
    const Report t = parse(theirs.out), o = parse(ours.out);
    EXPECT_EQ(t.verdict, expected_verdict) << theirs.out;
    EXPECT_EQ(o.verdict, t.verdict) << ours.out << "\nidiff:\n" << theirs.out;
    EXPECT_EQ(o.over_lines, t.over_lines) << ours.out << "\nidiff:\n" << theirs.out;
    EXPECT_EQ(o.max_line, t.max_line);
    const int idiff_status = t.verdict == "PASS" ? 0 : t.verdict == "WARNING" ? 1 : 2;
    EXPECT_EQ(theirs.status, idiff_status);
    EXPECT_EQ(ours.status, t.verdict == "PASS" ? 0 : 1);
  }

  // The cases every format gets (below); `step` is the smallest difference the format stores
  // (PNG: 1/255; EXR: anything, 1e-3 chosen), `ext` its extension.
  void every_case(const std::string& ext, float step);

  fs::path dir_;
};

constexpr int kW = 64, kH = 48;  // 3072 pixels: 1% is 30.72 pixels

// A smooth RGB image with values in [0.1, 0.9] (no clamping in PNG).
rvr::Image base_image(int w = kW, int h = kH) {
  rvr::Image img{w, h, 3, {"R", "G", "B"}, std::vector<float>(size_t(w) * h * 3)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        img.at(x, y, c) = 0.1f + 0.8f * float((x * (c + 1) + y * (3 - c)) % 97) / 96.0f;
  return img;
}

// Pixels 0, 7, 14, ... (every 7th in scan order) up to `count` of them, channel `c` moved by
// `delta`.
rvr::Image with_pixels_moved(rvr::Image img, int count, float delta, int c = 1) {
  for (int k = 0; k < count; ++k) {
    const int p = (7 * k) % (kW * kH);
    img.pixels[size_t(p) * 3 + size_t(c)] += delta;
  }
  return img;
}

void DiffVsIdiff::every_case(const std::string& ext, float step) {
  const auto check = [&](const fs::path& a, const fs::path& b, const std::string& options,
                         const std::string& verdict,
                         const std::string& what) { same_verdict(a, b, options, verdict, what); };
  const rvr::Image base = base_image();
  const fs::path a = save("a" + ext, base);
  check(a, a, "", "PASS", "identical");

  // 5 pixels (0.163%) over 1e-6 by 2 steps: FAILURE; allowed by --failpercent 1 (30.72 pixels)
  // they still warn (--warnpercent 0): WARNING; allowed by both: PASS.
  const fs::path few = save("few" + ext, with_pixels_moved(base, 5, 2 * step));
  check(a, few, "", "FAILURE", "a few pixels over");
  check(a, few, "--failpercent 1", "WARNING", "a few pixels over, allowed to fail");
  check(a, few, "--failpercent 1 --warnpercent 1", "PASS", "a few pixels over, allowed");
  // 31 pixels is just over 1% (30.72), 30 just under.
  const fs::path p31 = save("p31" + ext, with_pixels_moved(base, 31, 2 * step));
  const fs::path p30 = save("p30" + ext, with_pixels_moved(base, 30, 2 * step));
  check(a, p31, "--failpercent 1 --warnpercent 1", "FAILURE", "31 pixels: over 1%");
  check(a, p30, "--failpercent 1 --warnpercent 1", "PASS", "30 pixels: under 1%");

  // Many pixels (1000, 32.6%): over a 10% allowance, under a 40% one.
  const fs::path many = save("many" + ext, with_pixels_moved(base, 1000, 3 * step));
  check(a, many, "--failpercent 10 --warnpercent 10", "FAILURE", "many pixels over");
  check(a, many, "--failpercent 40 --warnpercent 40", "PASS", "many pixels, allowed");

  // --hardfail: within the percentage allowed, but one channel over the hard limit fails.
  const fs::path big = save("big" + ext, with_pixels_moved(base, 3, 20 * step, 2));
  check(a, big, "--failpercent 1 --warnpercent 1 --hardfail " + std::to_string(15 * step),
        "FAILURE", "hardfail below the largest difference");
  check(a, big, "--failpercent 1 --warnpercent 1 --hardfail " + std::to_string(25 * step), "PASS",
        "hardfail above the largest difference");
  check(a, big, "--failpercent 1 --hardfail " + std::to_string(25 * step), "WARNING",
        "hardfail above, warnings not allowed");

  // Warn-only: the differences (4 steps) are over the warn threshold and under the fail one.
  // idiff (2.4) passes an image with no failing pixel, whatever its warnings.
  const fs::path warn = save("warn" + ext, with_pixels_moved(base, 200, 4 * step, 0));
  check(a, warn, "--fail " + std::to_string(10 * step) + " --warn " + std::to_string(step), "PASS",
        "over warn, under fail");
  check(a, warn, "--fail " + std::to_string(2 * step) + " --warn " + std::to_string(step),
        "FAILURE", "over both");

  // Unrelated images: most pixels differ.
  rvr::Image other = base;
  for (size_t i = 0; i < other.pixels.size(); ++i)
    other.pixels[i] = 0.1f + 0.8f * float((i * 7919) % 101) / 100.0f;
  const fs::path unrelated = save("unrelated" + ext, other);
  check(a, unrelated, "", "FAILURE", "unrelated");
  check(a, unrelated, "--fail 1 --warn 1", "PASS", "unrelated, nothing can exceed 1");
}

TEST_F(DiffVsIdiff, ExrPairs) {
  every_case(".exr", 1e-3f);

  // Differences below the default thresholds (1e-6): 5e-7 on every channel of every pixel,
  // computed in float (so a few round to just over 5e-7, none near 1e-6): PASS, 0 pixels.
  const rvr::Image base = base_image();
  rvr::Image tiny = base;
  for (float& v : tiny.pixels) v += 5e-7f;
  const fs::path a = dir_ / "a.exr";
  same_verdict(a, save("tiny.exr", tiny), "", "PASS", "below 1e-6");
  // Differences that straddle the threshold: 0.5 against 0.5 + k ulp (ulp 5.96e-8; k = 16, 17,
  // 18: 0.954e-6, 1.013e-6, 1.073e-6) and 1.0 against 1 + k ulp (ulp 1.19e-7; k = 8, 9: 0.954e-6,
  // 1.073e-6): 3 of the 5 pixels are over 1e-6.
  rvr::Image edge = base, edge_b = base;
  const float ulps[5] = {16, 17, 18, 8, 9};
  for (int k = 0; k < 5; ++k) {
    const float v = k < 3 ? 0.5f : 1.0f;
    edge.at(k, 0, 0) = v;
    edge_b.at(k, 0, 0) = v + ulps[k] * (k < 3 ? 5.9604645e-8f : 1.1920929e-7f);
  }
  same_verdict(save("edge_a.exr", edge), save("edge_b.exr", edge_b), "", "FAILURE",
               "at the threshold");
}

TEST_F(DiffVsIdiff, PngPairs) {
  every_case(".png", 1.0f / 255.0f);
}

// The README's `rvr diff` example, with the options it shows (read from README.md), says what
// its text promises on images like the demo's: PASS when at most 0.1% of the pixels differ by
// more than 0.01, however many differ by less; FAILURE beyond. With --fail and --failpercent
// alone the warn threshold stays 1e-6 and such a pair is a WARNING (exit 1).
TEST_F(DiffVsIdiff, ReadmeExampleSaysWhatItPromises) {
  const std::string readme = slurp(fs::path(RVR_SOURCE_DIR) / "README.md");
  const std::string example = "rvr diff rvr-out/raster.png rvr-out/raytrace.png";
  const size_t at = readme.find(example);
  ASSERT_NE(at, std::string::npos) << "README.md has no `" << example << "` example";
  const std::string line = readme.substr(at, readme.find('\n', at) - at);
  // Its threshold options, without -o.
  std::string options;
  static const std::regex option(
      R"(--(fail|failpercent|hardfail|warn|warnpercent|hardwarn) (\S+))");
  for (auto it = std::sregex_iterator(line.begin(), line.end(), option);
       it != std::sregex_iterator(); ++it) {
    if (!options.empty()) options += ' ';
    options += it->str();
  }
  ASSERT_NE(options.find("--fail 0.01"), std::string::npos) << line;
  ASSERT_NE(options.find("--failpercent 0.1"), std::string::npos) << line;

  // 3072 pixels: 0.1% is 3.07. Many pixels one 8-bit step apart (about 0.004: under 0.01), as
  // along the demo's shading, and a few far apart, as along its silhouettes.
  const rvr::Image base = base_image();
  const fs::path a = save("a.png", base);
  const rvr::Image shaded = with_pixels_moved(base, 400, 1.0f / 255.0f, 0);
  const fs::path few = save("few.png", with_pixels_moved(shaded, 3, 0.3f, 2));
  const fs::path many = save("many.png", with_pixels_moved(shaded, 4, 0.3f, 2));
  same_verdict(a, few, options, "PASS", "README example, 3 pixels (0.098%) over 0.01");
  same_verdict(a, many, options, "FAILURE", "README example, 4 pixels (0.13%) over 0.01");
}

// Images that cannot be compared: rvr exits 2 with one error line; idiff does not PASS.
TEST_F(DiffVsIdiff, DifferentSizesAreBadInput) {
  const fs::path a = save("a.exr", base_image()), b = save("b.exr", base_image(kW + 1, kH));
  const Outcome ours = run(std::string(RVR_BINARY) + " diff " + a.string() + " " + b.string());
  EXPECT_EQ(ours.status, 2);
  const Outcome theirs = run(std::string(kIdiff) + " " + a.string() + " " + b.string());
  EXPECT_NE(theirs.status, 0);
  EXPECT_EQ(parse(theirs.out).verdict, "FAILURE");
  const Outcome missing =
      run(std::string(RVR_BINARY) + " diff " + a.string() + " " + (dir_ / "nope.exr").string());
  EXPECT_EQ(missing.status, 2);
}

}  // namespace
