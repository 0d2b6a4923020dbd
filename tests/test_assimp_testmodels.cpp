// Model files no one here made, as a newcomer meets them (issue 34): Debian's assimp-testmodels
// (TEST_PACKAGES in the Makefile; a missing package fails these tests rather than skipping
// them). File cameras that show a part of the model or a close-up, textures named by Windows
// tools, and `rvr scenes --export` of a textured model whose folder then moves. What a picture
// shows is computed here independently of rvr's judge: the model's vertices projected through
// the camera by GLM.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <initializer_list>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/texture.h"
#include "rvr/scene_io/scene_loader.h"

namespace fs = std::filesystem;

namespace {

const fs::path kModels = "/usr/share/assimp/models";

class AssimpTestModels : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::is_directory(kModels))
        << kModels << " is missing: install Debian's assimp-testmodels (make deps)";
    dir_ = fs::temp_directory_path() /
           ("rvr_testmodels_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs rvr with `args`; its status, and stderr in `err`.
int run_rvr(const std::string& args, const fs::path& scratch, std::string* err) {
  const fs::path err_file = scratch / "stderr.txt";
  const std::string cmd = "timeout -k 10 " + std::to_string(RVR_PROCESS_TIMEOUT) + " " +
                          std::string(RVR_BINARY) + " " + args + " >/dev/null 2>" +
                          err_file.string() + " </dev/null";
  const int raw = std::system(cmd.c_str());
  *err = slurp(err_file);
  fs::remove(err_file);
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string all_warnings(const rvr::Scene& s) {
  std::string out;
  for (const std::string& w : s.warnings) out += w + "\n";
  return out.empty() ? "no warnings" : out;
}

std::string warning_with(const rvr::Scene& s, const std::string& part) {
  for (const std::string& w : s.warnings)
    if (w.find(part) != std::string::npos) return w;
  return {};
}

// The share of the model's vertices inside the frame of the scene's camera (GLM's projection
// and clip test), the independent measure of what the picture shows.
double vertices_in_frame(const rvr::Scene& s) {
  const rvr::Camera& c = s.camera;
  const glm::mat4 m =
      glm::perspective(glm::radians(c.fov_y_deg), float(s.image.width) / float(s.image.height),
                       c.near, c.far) *
      glm::lookAt(c.eye, c.target, c.up);
  size_t in = 0, all = 0;
  for (const rvr::Object& o : s.objects) {
    for (const glm::vec3& p : o.mesh.positions) {
      const glm::vec4 q = m * glm::vec4(p, 1.0f);
      ++all;
      in += q.w > 0.0f && std::fabs(q.x) <= q.w && std::fabs(q.y) <= q.w && std::fabs(q.z) <= q.w;
    }
  }
  return all ? double(in) / double(all) : 0.0;
}

// Collada/earthCylindrical.DAE names its image `\..\LWO\LWO2\MappingModes\EarthCylindric.jpg`
// (from the model's folder, in another case than the file's); FBX/spider.fbx names
// `D:\projects\assimp_int\test\models\OBJ\drkwood2.jpg` and three more, which lie in the
// sibling folder OBJ/. Every one is found and decoded, with no warning about textures.
TEST_F(AssimpTestModels, TexturesNamedByWindowsToolsAreFound) {
  rvr::Scene earth =
      rvr::load_scene((kModels / "Collada" / "earthCylindrical.DAE").string()).value();
  EXPECT_EQ(warning_with(earth, "texture"), "") << all_warnings(earth);
  ASSERT_EQ(earth.textures.size(), 1u);
  EXPECT_EQ(fs::path(earth.textures[0].resolved).lexically_normal(),
            kModels / "LWO" / "LWO2" / "MappingModes" / "earthCylindric.jpg");
  EXPECT_TRUE(earth.textures[0].mips);

  rvr::Scene spider = rvr::load_scene((kModels / "FBX" / "spider.fbx").string()).value();
  EXPECT_EQ(warning_with(spider, "texture"), "") << all_warnings(spider);
  ASSERT_EQ(spider.textures.size(), 4u);
  for (const rvr::Texture& t : spider.textures) {
    SCOPED_TRACE(t.file);
    EXPECT_EQ(t.file.rfind("D:\\projects\\assimp_int\\test\\models\\OBJ\\", 0), 0u);
    const fs::path found(t.resolved);
    EXPECT_EQ(found.parent_path(), kModels / "OBJ");
    EXPECT_EQ(lower(found.filename().string()), lower(t.file.substr(t.file.rfind('\\') + 1)))
        << "the name after the last backslash";
    EXPECT_TRUE(t.mips);
  }
}

// FBX/spider.fbx's camera shows a grey close-up (about a tenth of the spider's vertices in
// frame), FBX/huesitos.fbx's and the 2CylinderEngine's cut parts off: each is replaced by the
// framing camera, which shows every vertex, with a warning saying why. Collada/duck.dae's and
// glTF2/cameras/Cameras.gltf's cameras show the whole model and are kept.
TEST_F(AssimpTestModels, FileCamerasThatDoNotFrameTheModelAreReplaced) {
  for (const char* name : {"FBX/spider.fbx", "FBX/huesitos.fbx",
                           "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"}) {
    SCOPED_TRACE(name);
    const std::string path = (kModels / name).string();
    rvr::SceneOverrides keep;
    keep.judge_file_camera = false;
    rvr::Scene as_is = rvr::load_scene(path, keep).value();
    EXPECT_LT(vertices_in_frame(as_is), 0.9);
    rvr::Scene s = rvr::load_scene(path).value();
    const std::string w = warning_with(s, "the file's camera");
    EXPECT_EQ(w.rfind(path + ": the file's camera sees ", 0), 0u) << all_warnings(s);
    EXPECT_NE(w.find("framing the model instead (--camera file-always keeps it)"),
              std::string::npos)
        << w;
    rvr::SceneOverrides automatic;
    automatic.camera = rvr::FromFile::Auto;
    rvr::Scene framed = rvr::load_scene(path, automatic).value();
    EXPECT_EQ(s.camera.eye, framed.camera.eye);
    EXPECT_EQ(s.camera.target, framed.camera.target);
    EXPECT_EQ(vertices_in_frame(s), 1.0);
  }
  for (const char* name : {"Collada/duck.dae", "glTF2/cameras/Cameras.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = (kModels / name).string();
    rvr::Scene s = rvr::load_scene(path).value();
    EXPECT_EQ(warning_with(s, "camera"), "") << all_warnings(s);
    rvr::SceneOverrides automatic;
    automatic.camera = rvr::FromFile::Auto;
    EXPECT_NE(s.camera.eye, rvr::load_scene(path, automatic)->camera.eye) << "the file's own";
    EXPECT_EQ(vertices_in_frame(s), 1.0);
  }
}

// The replacement's warning reaches metrics.json and report.html, not only stderr.
TEST_F(AssimpTestModels, ReplacedCameraWarningReachesMetricsAndReport) {
  const std::string path = (kModels / "FBX" / "huesitos.fbx").string();
  std::string err;
  ASSERT_EQ(run_rvr("compare " + path + " -r softraster,raytrace --image 64x48 -q -o " +
                        (dir_ / "out").string(),
                    dir_, &err),
            0)
      << err;
  const std::string warning = path + ": the file's camera sees ";
  EXPECT_NE(err.find("warning: " + warning), std::string::npos) << err;
  EXPECT_NE(slurp(dir_ / "out" / "metrics.json").find(warning), std::string::npos);
  EXPECT_NE(slurp(dir_ / "out" / "report.html").find("the file&#39;s camera sees "),
            std::string::npos);
}

// `rvr scenes --export Collada/duck.dae -o DIR/duck.json`, then DIR moved elsewhere (one
// folder deeper): the scene renders with its texture and no warning. The texture, outside DIR,
// is named by its absolute path; with --copy-assets it is copied into DIR and named there.
TEST_F(AssimpTestModels, ExportedSceneKeepsItsTextureAfterItsFolderMoves) {
  const std::string duck = (kModels / "Collada" / "duck.dae").string();
  for (const bool copy : {false, true}) {
    SCOPED_TRACE(copy ? "--copy-assets" : "named where it is");
    const fs::path out = dir_ / "export", moved = dir_ / "elsewhere" / "deeper" / "moved";
    fs::remove_all(out);
    fs::remove_all(dir_ / "elsewhere");
    std::string err;
    ASSERT_EQ(run_rvr("scenes --export " + duck + " -o " + (out / "duck.json").string() +
                          (copy ? " --copy-assets" : ""),
                      dir_, &err),
              0)
        << err;
    const std::string json = slurp(out / "duck.json");
    const std::string named =
        copy ? "duck.texture0.tga" : (kModels / "Collada" / "duckCM.tga").string();
    EXPECT_NE(json.find("\"file\": \"" + named + "\""), std::string::npos) << json;
    fs::create_directories(moved.parent_path());
    fs::rename(out, moved);
    rvr::Expected<rvr::Scene> s = rvr::load_scene((moved / "duck.json").string());
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_TRUE(s->warnings.empty()) << all_warnings(*s);
    ASSERT_EQ(s->textures.size(), 1u);
    EXPECT_TRUE(s->textures[0].mips);
    EXPECT_EQ(fs::path(s->textures[0].resolved),
              copy ? moved / "duck.texture0.tga" : kModels / "Collada" / "duckCM.tga");
    ASSERT_EQ(run_rvr("render " + (moved / "duck.json").string() + " -r softraster --image 32x24 " +
                          "-q -o " + (dir_ / "duck.png").string(),
                      dir_, &err),
              0)
        << err;
    EXPECT_EQ(err, "");
  }
}

}  // namespace
