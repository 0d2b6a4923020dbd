// Every input the fuzzers (tests/fuzz, `make fuzz`) ever broke the loader with, and the seed
// corpora, replayed in the normal test run: the loader must return a scene or a well-formed
// error (bad input, one line, naming the file), never crash or hang. fuzz_common.h aborts on
// a malformed error, which fails the test binary.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_common.h"

namespace fs = std::filesystem;

namespace {

// The files of tests/fuzz/SUB. A missing folder is a failure, not nothing to replay: git keeps
// no empty folder, and a renamed or lost one would otherwise pass silently.
std::vector<fs::path> files_in(const std::string& sub) {
  std::vector<fs::path> out;
  fs::path dir = fs::path(RVR_SOURCE_DIR) / "tests" / "fuzz" / sub;
  EXPECT_TRUE(fs::is_directory(dir)) << dir << " is missing";
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file()) out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

const fs::path& dir() {
  static const fs::path& d = rvr::fuzz::scratch_dir(RVR_SOURCE_DIR "/scenes/models");
  return d;
}

// Replays every file of tests/fuzz/SUB and returns how many there were.
size_t replay(const std::string& sub, bool mesh) {
  size_t count = 0;
  for (const fs::path& p : files_in(sub)) {
    SCOPED_TRACE(p.string());
    std::vector<uint8_t> bytes = read_bytes(p);
    rvr::Expected<rvr::Scene> s =
        mesh ? rvr::fuzz::load_mesh_bytes(dir(), bytes.data(), bytes.size())
             : rvr::fuzz::load_scene_text(dir(), bytes.data(), bytes.size());
    // load_*() abort on a malformed error (not bad input, not one line, no file name first).
    if (!s.ok()) {
      EXPECT_EQ(s.error().kind, rvr::ErrorKind::BadInput);
    }
    ++count;
  }
  return count;
}

}  // namespace

// Each harness replays at least one regression input and one seed: an empty or missing folder
// fails here instead of replaying nothing.
TEST(FuzzRegressions, SceneInputsLoadOrFailCleanly) {
  EXPECT_GE(replay("regressions/scene", false), 1u);
  EXPECT_GE(replay("corpus/scene", false), 1u);
}

TEST(FuzzRegressions, MeshInputsLoadOrFailCleanly) {
  EXPECT_GE(replay("regressions/mesh", true), 1u);
  EXPECT_GE(replay("corpus/mesh", true), 1u);
}

// Every folder of regressions/ and corpus/ is a harness's: one named otherwise (a typo, a
// harness renamed) would never be replayed.
TEST(FuzzRegressions, EveryFolderBelongsToAHarness) {
  for (const char* kind : {"regressions", "corpus"}) {
    const fs::path dir = fs::path(RVR_SOURCE_DIR) / "tests" / "fuzz" / kind;
    ASSERT_TRUE(fs::is_directory(dir)) << dir;
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string name = e.path().filename().string();
      EXPECT_TRUE(e.is_directory() && (name == "scene" || name == "mesh")) << e.path();
    }
  }
}

TEST(FuzzRegressions, ValidSeedsLoad) {
  for (const char* name : {"full.json", "minimal.json", "gallery.json"}) {
    std::vector<uint8_t> bytes =
        read_bytes(fs::path(RVR_SOURCE_DIR) / "tests/fuzz/corpus/scene" / name);
    rvr::Expected<rvr::Scene> s = rvr::fuzz::load_scene_text(dir(), bytes.data(), bytes.size());
    EXPECT_TRUE(s.ok()) << name << ": " << (s.ok() ? "" : s.error().message);
  }
  for (const char* name : {"tri.obj", "tri.ply", "tri_binary.ply", "tri.gltf", "crystal.3ds",
                           "tri.stl", "tri.off", "tri.glb"}) {
    std::vector<uint8_t> bytes =
        read_bytes(fs::path(RVR_SOURCE_DIR) / "tests/fuzz/corpus/mesh" / name);
    rvr::Expected<rvr::Scene> s = rvr::fuzz::load_mesh_bytes(dir(), bytes.data(), bytes.size());
    EXPECT_TRUE(s.ok()) << name << ": " << (s.ok() ? "" : s.error().message);
  }
}
