// Every input the fuzzers (tests/fuzz, `make fuzz`) ever broke the loader with, and the seed
// corpora, replayed in the normal test run: each must give its expected outcome, a scene or a
// bad-input error saying what is wrong (one line, naming the file), never a crash or hang.
// fuzz_common.h aborts on a malformed error, which fails the test binary.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>  // IWYU pragma: keep (std::ifstream/ofstream: iwyu takes <iosfwd> for them)
#include <initializer_list>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz/fuzz_common.h"
#include "rvr/core/expected.h"
#include "rvr/core/scene.h"

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

// What loading an input must give: success (`error` empty), or a bad-input error whose message
// contains `error` (after the file name that every message starts with).
struct Expect {
  const char* file;
  const char* error;
};

// Inputs that once crashed, hung or exhausted the loader: each is now refused, for its reason.
const std::vector<Expect> kSceneRegressions = {
    {"nesting_past_the_stack.json", ":1:592: JSON syntax: nesting deeper than 512"},
};

// The scene seeds: valid scenes load; the rest are refused, each for the fault it was made with.
const std::vector<Expect> kSceneSeeds = {
    {"bad_camera.json", "camera.up: must not be parallel to target - eye"},
    {"bad_image.json", "image.width: must be an integer in 1..16384, got number 0"},
    {"bad_utf8.json", ":1:24: JSON syntax: invalid string: ill-formed UTF-8 byte"},
    {"blob.json", ""},
    {"deep.json", ":1:513: JSON syntax: nesting deeper than 512"},
    {"deep_csg.json", "top level: unknown key 'a'"},
    {"deep_csg_object.json", "csg tree nested deeper than 64 levels"},
    {"duplicate_key.json", "camera: duplicate key"},
    {"empty.json", ":1:1: JSON syntax: unexpected end of input (the file is empty)"},
    {"full.json", ""},
    {"gallery.json", ""},
    {"mesh_is_dir.json", "objects[0].file: cannot read 'models': Is a directory"},
    {"minimal.json", ""},
    {"missing_mesh.json", "objects[0].file: cannot read 'models/missing.obj': No such file"},
    {"negative_radius.json", "objects[0].radius: must be > 0, got -1"},
    {"overflow.json", "camera.eye[2]: must be a finite number, got 1e999 (overflows)"},
    {"spaces.json", ":2:3: JSON syntax: unexpected end of input (the file is empty)"},
    {"torus.json", ""},
    {"trailing_comma.json", ":1:47: JSON syntax: expected a quoted key, got '}' (trailing comma?)"},
    {"truncated_blob.json", ":17:63: JSON syntax: unexpected end of input (expected a value)"},
    {"truncated_gallery.json",
     ":19:47: JSON syntax: unexpected end of input (expected ',' or '}')"},
    {"truncated_torus.json", ":15:13: JSON syntax: unexpected end of input (expected ':')"},
    {"typo.json", "unknown key 'objcts' (did you mean 'objects'?)"},
};

// Mesh inputs that once crashed, hung, leaked or exhausted the loader (or Assimp under it).
// A crash inside Assimp is caught by the child process that imports and becomes the file's error:
// "(signal 11)" natively, "(exit status 1)" under AddressSanitizer, which reports the SEGV and
// exits the child itself; either way the crash is contained and named.
const std::vector<Expect> kMeshRegressions = {
    {"dae_float_array_without_count_segv", "cannot read 'mesh.dae': the importer crashed ("},
    {"dae_triangle_count_past_the_file_oom",
     "cannot read 'mesh.dae': the file declares more data than it holds"},
    {"off_faces_without_indices",
     "cannot read 'mesh.off': Validation failed: aiMesh::mFaces[0].mIndices is nullptr"},
    {"off_vertex_count_past_the_file_oom",
     "cannot read 'mesh.off': the file declares more data than it holds"},
    {"ply_ascii_vertex_count_past_the_file_oom",
     "cannot read 'mesh.ply': the file declares more data than it holds"},
    {"ply_bad_header_segv", "cannot read 'mesh.ply': PLY header has no end_header line"},
    {"ply_bad_vertex_assimp_leak", "cannot read 'mesh.ply': Cannot parse string \"(0?\""},
    {"ply_face_index_out_of_range_aborts", "'mesh.ply': face 0 of mesh 0 has no vertices"},
    {"ply_header_without_end_hangs", "cannot read 'mesh.ply': PLY header has no end_header line"},
};

// The mesh seeds: one valid file per importer loads; the faulty ones are refused.
const std::vector<Expect> kMeshSeeds = {
    {"crystal.3ds", ""},
    {"empty.obj", "cannot read 'mesh.obj': OBJ-file is too small."},
    {"nan.obj", "'mesh.obj': vertex 0 of mesh 0 has a non-finite coordinate"},
    {"neg_index.obj", "cannot read 'mesh.obj': OBJ: vertex index out of range"},
    {"quad.obj", ""},
    {"tri.dae", ""},
    {"tri.glb", ""},
    {"tri.gltf", ""},
    {"tri.obj", ""},
    {"tri.off", ""},
    {"tri.ply", ""},
    {"tri.stl", ""},
    {"tri_binary.ply", ""},
    {"tri_binary.stl", ""},
    {"tri_smooth.obj", ""},
    {"tri_smooth.ply", ""},
};

// Replays every file of tests/fuzz/SUB against its expected outcome in `table`; a file without
// an entry, or an entry without a file, fails (a new regression input needs its outcome).
void replay(const std::string& sub, bool mesh, const std::vector<Expect>& table) {
  std::set<std::string> seen;
  for (const fs::path& p : files_in(sub)) {
    const std::string name = p.filename().string();
    SCOPED_TRACE(sub + "/" + name);
    seen.insert(name);
    std::vector<uint8_t> bytes = read_bytes(p);
    // load_*() abort on a malformed error (not bad input, not one line, no file name first).
    rvr::Expected<rvr::Scene> s =
        mesh ? rvr::fuzz::load_mesh_bytes(dir(), bytes.data(), bytes.size())
             : rvr::fuzz::load_scene_text(dir(), bytes.data(), bytes.size());
    const std::string got = s.ok() ? "" : s.error().message;
    std::printf("%s/%s: %s\n", sub.c_str(), name.c_str(), s.ok() ? "loads" : got.c_str());
    auto it =
        std::find_if(table.begin(), table.end(), [&](const Expect& e) { return name == e.file; });
    if (it == table.end()) {
      ADD_FAILURE() << "no expected outcome for " << name
                    << " (it gives: " << (s.ok() ? "a scene" : got) << ")";
      continue;
    }
    if (std::string(it->error).empty()) {
      EXPECT_TRUE(s.ok()) << got;
    } else {
      ASSERT_FALSE(s.ok()) << "loads; expected an error containing \"" << it->error << "\"";
      EXPECT_EQ(s.error().kind, rvr::ErrorKind::BadInput);
      EXPECT_NE(got.find(it->error), std::string::npos)
          << "expected \"" << it->error << "\" in: " << got;
    }
  }
  for (const Expect& e : table)
    EXPECT_TRUE(seen.count(e.file)) << sub << "/" << e.file << " is missing";
}

}  // namespace

// Each harness replays its regression inputs and its seeds, each against its expected outcome;
// an empty or missing folder fails (its table's files are missing).
TEST(FuzzRegressions, SceneInputsGiveTheirExpectedOutcome) {
  replay("regressions/scene", false, kSceneRegressions);
  replay("corpus/scene", false, kSceneSeeds);
}

TEST(FuzzRegressions, MeshInputsGiveTheirExpectedOutcome) {
  replay("regressions/mesh", true, kMeshRegressions);
  replay("corpus/mesh", true, kMeshSeeds);
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
