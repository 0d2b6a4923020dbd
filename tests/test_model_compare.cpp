// `rvr compare MODEL` out of the box on bare model files (no scene file, no options but the
// output folder): OBJ + MTL, PLY (Blender's header, vertex colours), glTF and 3DS, each a unit
// cube of one known colour. The two loop orders must agree on the ids, the model must fill a
// sensible part of the frame, and its colour must be the file's. Then every model file of the
// corpus and of scenes/models through both z-buffers, with the loader's warnings in metrics.json.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "model_corpus.h"
#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/scene_io/scene_loader.h"

namespace fs = std::filesystem;
namespace corpus = rvr::test::corpus;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class ModelCompare : public corpus::ModelDirTest {
 protected:
  const char* folder_prefix() const override { return "rvr_model_compare_"; }

  // rvr compare MODEL -o DIR [OPTIONS], as a process; returns its exit status (stderr kept for
  // messages).
  int compare(const std::string& model, const fs::path& out, std::string* err,
              const std::string& options = "") {
    fs::path err_file = dir_ / "stderr.txt";
    std::string cmd = "timeout -k 10 " + std::to_string(RVR_PROCESS_TIMEOUT) + " " +
                      std::string(RVR_BINARY) + " compare " + model + " -q -o " + out.string() +
                      " " + options + " >/dev/null 2>" + err_file.string() + " </dev/null";
    int raw = std::system(cmd.c_str());
    *err = slurp(err_file);
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  }

  // Runs the comparison and checks ids, coverage and colour. `colour` is the file's diffuse
  // colour (linear).
  void expect_compare_works(const std::string& model, glm::vec3 colour) {
    SCOPED_TRACE(model);
    fs::path out = dir_ / "out";
    std::string err;
    ASSERT_EQ(compare(model, out, &err), 0) << err;
    nlohmann::json m = nlohmann::json::parse(slurp(out / "metrics.json"));
    EXPECT_GE(m["visibility"]["id_agreement"].get<double>(), 0.999);
    for (const char* name : {"raster.png", "raytrace.png"}) {
      SCOPED_TRACE(name);
      rvr::Expected<rvr::Image> read = rvr::read_image((out / name).string());
      ASSERT_TRUE(read.ok()) << read.error().message;
      const rvr::Image& im = *read;
      ASSERT_GE(im.channels, 3);
      // The background is black; the cube is lit by at least the ambient term (0.15 x its
      // diffuse colour, every channel of which is above 0.05 here), so it is not black.
      size_t covered = 0;
      glm::dvec3 sum(0.0);
      for (int y = 0; y < im.height; ++y) {
        for (int x = 0; x < im.width; ++x) {
          glm::vec3 c(im.at(x, y, 0), im.at(x, y, 1), im.at(x, y, 2));
          if (c.r + c.g + c.b == 0.0f) continue;
          ++covered;
          sum += glm::dvec3(c);
        }
      }
      double fraction = double(covered) / double(im.width * im.height);
      // The framing puts the bounding sphere (radius sqrt(3)/2) across 1/1.1 of the image
      // height: the cube seen from three-quarters above covers about 0.7 of that circle, about
      // 0.3 of a 4:3 frame. Sensible: between a tenth and two thirds of the frame.
      EXPECT_GT(fraction, 0.10);
      EXPECT_LT(fraction, 0.67);
      // The colour family: the mean covered colour's channels in the order of the file's.
      // (Shading scales all channels alike and white light keeps their order; PNG's sRGB
      // curve is monotonic.)
      glm::dvec3 mean = sum / double(std::max<size_t>(covered, 1));
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          if (colour[a] > colour[b] + 0.2f) {
            EXPECT_GT(mean[a], mean[b] + 0.05) << "channel " << a << " vs " << b;
          }
        }
      }
    }
  }
};

TEST_F(ModelCompare, BareObjWithMtl) {
  write("paint.mtl", "newmtl paint\nKd 0.9 0.15 0.1\n");
  expect_compare_works(write("cube.obj", corpus::obj_cube("mtllib paint.mtl\n", "paint")),
                       {0.9f, 0.15f, 0.1f});
}

TEST_F(ModelCompare, BarePlyFromBlender) {
  expect_compare_works(write("cube.ply", corpus::blender_ply_cube(30, 200, 40)),
                       glm::vec3(30, 200, 40) / 255.0f);
}

TEST_F(ModelCompare, BareGltf) {
  corpus::GltfExtras e;
  e.base_colour = {0.1f, 0.2f, 0.9f, 1.0f};
  expect_compare_works(write("cube.gltf", corpus::gltf_json(e, false)), {0.1f, 0.2f, 0.9f});
}

TEST_F(ModelCompare, Bare3ds) {
  expect_compare_works(write("cube.3ds", corpus::cube_3ds(230, 200, 20)),
                       glm::vec3(230, 200, 20) / 255.0f);
}

// Every model file of the corpus and of scenes/models as a bare model file, rendered by both
// z-buffers (GL through OSMesa, softraster) at 160x120: `rvr compare` exits 0 under
// --fail-below-agreement 0.999 (which also fails a pair with nothing visible), metrics.json's
// id agreement is at least 0.999, each image shows the model on more than 1 % of its pixels,
// and every warning the loader gives for the file (rvr::load_scene, the library on its own) is
// in metrics.json's warnings. Files with known faults (STL normals against the winding and a
// degenerate facet, a glTF texture on a mesh without texture coordinates) make sure some
// warnings are checked.
TEST_F(ModelCompare, EveryModelFileRendersAndAgreesWithBothZBuffers) {
  std::vector<std::string> files;
  for (const corpus::CorpusFile& f : corpus::every_file()) {
    std::string p = write(f.name, f.bytes);
    if (f.model) files.push_back(p);
  }
  const fs::path shipped = fs::path(RVR_SOURCE_DIR) / "scenes" / "models";
  for (const fs::directory_entry& e : fs::directory_iterator(shipped)) {
    if (rvr::is_model_file_name(e.path().string())) files.push_back(e.path().string());
  }
  ASSERT_GE(files.size(), 18u);
  rvr::SceneOverrides size;
  size.width = 160;
  size.height = 120;
  size_t warnings_checked = 0;
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string& model = files[i];
    SCOPED_TRACE(model);
    fs::path out = dir_ / ("out" + std::to_string(i));
    std::string err;
    ASSERT_EQ(compare(model, out, &err,
                      "-r raster,softraster --image 160x120 --fail-below-agreement 0.999"),
              0)
        << err;
    nlohmann::json m = nlohmann::json::parse(slurp(out / "metrics.json"));
    const nlohmann::json& v = m["visibility"];
    const double agreement = v["id_agreement"].get<double>();
    const size_t pixels = v["pixels"].get<size_t>();
    EXPECT_EQ(pixels, 160u * 120u);
    EXPECT_GE(agreement, 0.999);
    EXPECT_GT(v["covered_a"].get<size_t>() * 100, pixels);
    EXPECT_GT(v["covered_b"].get<size_t>() * 100, pixels);
    rvr::Expected<rvr::Scene> loaded = rvr::load_scene(model, size);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    const std::vector<std::string> reported = m["warnings"].get<std::vector<std::string>>();
    for (const std::string& w : loaded->warnings) {
      EXPECT_NE(std::find(reported.begin(), reported.end(), w), reported.end()) << w;
      ++warnings_checked;
    }
    std::printf("%-60s id agreement %.5f  covered %zu / %zu  warnings %zu\n", model.c_str(),
                agreement, v["covered_a"].get<size_t>(), v["covered_b"].get<size_t>(),
                reported.size());
  }
  EXPECT_GE(warnings_checked, 3u);
}

}  // namespace
