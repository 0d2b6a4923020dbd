// `rvr compare MODEL` out of the box on bare model files (no scene file, no options but the
// output folder): OBJ + MTL, PLY (Blender's header, vertex colours), glTF and 3DS, each a unit
// cube of one known colour. The two loop orders must agree on the ids, the model must fill a
// sensible part of the frame, and its colour must be the file's.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "model_corpus.h"
#include "rvr/shared/image_io.h"

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

  // rvr compare MODEL -o DIR, as a process; returns its exit status (stderr kept for messages).
  int compare(const std::string& model, const fs::path& out, std::string* err) {
    fs::path err_file = dir_ / "stderr.txt";
    std::string cmd = "timeout -k 10 " + std::to_string(RVR_PROCESS_TIMEOUT) + " " +
                      std::string(RVR_BINARY) + " compare " + model + " -q -o " + out.string() +
                      " >/dev/null 2>" + err_file.string() + " </dev/null";
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
  e.base_color = {0.1f, 0.2f, 0.9f, 1.0f};
  expect_compare_works(write("cube.gltf", corpus::gltf_json(e, false)), {0.1f, 0.2f, 0.9f});
}

TEST_F(ModelCompare, Bare3ds) {
  expect_compare_works(write("cube.3ds", corpus::cube_3ds(230, 200, 20)),
                       glm::vec3(230, 200, 20) / 255.0f);
}

}  // namespace
