// Tests of the rvr-scene/1 loader: values and defaults, error messages (file, JSON path,
// what), meshes in every shipped format, and the example scenes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>  // IWYU pragma: keep (std::ifstream/ofstream: iwyu takes <iosfwd> for them)
#include <glm/glm.hpp>
#include <initializer_list>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/disc.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/square.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/texture.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/prepared_renderer.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"
#include "rvr/scene_io/scene_writer.h"

namespace fs = std::filesystem;
using rvr::Expected;
using rvr::Scene;

namespace {

const std::string kCamera = R"("camera": {"eye": [0, 1, 4], "target": [0, 1, 0], "up": [0, 1, 0]})";

// A scene with the standard camera and the given extra top-level members.
std::string scene(const std::string& members) {
  return "{" + kCamera + ", " + members + "}";
}

std::string one_object(const std::string& object) {
  return scene(R"("objects": [)" + object + "]");
}

void write_file(const fs::path& path, const std::string& content) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out << content;
  ASSERT_TRUE(out.good()) << path;
}

bool near3(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
  return std::abs(a.x - b.x) <= eps && std::abs(a.y - b.y) <= eps && std::abs(a.z - b.z) <= eps;
}

::testing::AssertionResult has_position(const rvr::TriangleMesh& mesh, const glm::vec3& p) {
  for (const glm::vec3& q : mesh.positions) {
    if (near3(p, q)) return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "no vertex at (" << p.x << ", " << p.y << ", " << p.z << ")";
}

// A folder of its own under the system temp dir for each test, removed afterwards.
class SceneLoader : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("rvr_scene_loader_" + std::to_string(::getpid()) + "_" +
                                        info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  Expected<Scene> parse(const std::string& text) { return rvr::parse_scene(text, "t.json", dir_); }

  // Parses and expects success, printing the error otherwise.
  Scene parse_ok(const std::string& text) {
    Expected<Scene> s = parse(text);
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    return s.ok() ? std::move(s).value() : Scene{};
  }

  fs::path dir_;
};

// A unit quad in the xz plane (two triangles, normal +y) as OBJ, without normals.
const std::string kQuadObj =
    "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n"
    "f 1 4 3\nf 1 3 2\n";

// ---------------------------------------------------------------------------------------------
// Valid scenes

TEST_F(SceneLoader, EveryKeyParsesToTheRightValues) {
  write_file(dir_ / "models" / "quad.obj", kQuadObj);
  const std::string text = R"({
    "format": "rvr-scene/1",
    "image": {"width": 320, "height": 200, "background": [0.1, 0.2, 0.3], "samples_per_pixel": 4},
    "camera": {"eye": [0, 1, 4], "target": [0, 1, 0], "up": [0, 1, 0], "fov_y_deg": 60,
               "near": 0.5, "far": 50, "aperture_radius": 0.05, "focus_distance": 3.5},
    "ambient": [0.05, 0.06, 0.07],
    "materials": {
      "zeta":  {"diffuse": [0.1, 0.2, 0.3], "specular": [0.4, 0.5, 0.6], "emission": [1, 2, 3],
                "shininess": 50, "mirror": 0.25, "transparency": 0.5, "ior": 1.33},
      "alpha": {}
    },
    "lights": [
      {"type": "point", "position": [1, 2, 3], "intensity": [4, 5, 6]},
      {"type": "area", "corner": [-1, 4, -1], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2],
       "intensity": [8, 8, 8], "samples": 3},
      {"type": "area", "corner": [0, 4, 0], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1],
       "intensity": [1, 1, 1]}
    ],
    "objects": [
      {"name": "ball", "type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "zeta"},
      {"type": "plane", "point": [0, 0, 0], "normal": [0, 2, 0]},
      {"type": "plane", "point": [0, 0, -5], "normal": [0, 0, 1], "half_size": 3,
       "material": "alpha"},
      {"type": "triangle", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "material": "alpha"},
      {"name": "quad", "type": "mesh", "file": "models/quad.obj", "smooth": true,
       "material": "zeta",
       "transform": {"scale": 2, "rotate_deg": [0, 0, 90], "translate": [1, 2, 3]}},
      {"type": "csg", "op": "difference", "material": "zeta",
       "a": {"type": "sphere", "center": [0, 1, 0], "radius": 1},
       "b": {"op": "intersection",
             "a": {"center": [0.5, 1.5, 0.5], "radius": 0.6},
             "b": {"type": "sphere", "center": [0.6, 1.5, 0.5], "radius": 0.5}}}
    ]
  })";
  Scene s = parse_ok(text);
  EXPECT_EQ(s.source, "t.json");
  EXPECT_TRUE(s.warnings.empty());

  EXPECT_EQ(s.image.width, 320);
  EXPECT_EQ(s.image.height, 200);
  EXPECT_TRUE(near3(s.image.background, {0.1f, 0.2f, 0.3f}));
  EXPECT_EQ(s.image.samples_per_pixel, 4);

  EXPECT_TRUE(near3(s.camera.eye, {0, 1, 4}));
  EXPECT_TRUE(near3(s.camera.target, {0, 1, 0}));
  EXPECT_TRUE(near3(s.camera.up, {0, 1, 0}));
  EXPECT_FLOAT_EQ(s.camera.fov_y_deg, 60.0f);
  EXPECT_FLOAT_EQ(s.camera.near, 0.5f);
  EXPECT_FLOAT_EQ(s.camera.far, 50.0f);
  EXPECT_FLOAT_EQ(s.camera.aperture_radius, 0.05f);
  EXPECT_FLOAT_EQ(s.camera.focus_distance, 3.5f);
  EXPECT_TRUE(near3(s.ambient, {0.05f, 0.06f, 0.07f}));

  // The built-in grey first, then the file's materials in file order (not alphabetical).
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[0].name, rvr::default_material().name);
  EXPECT_TRUE(near3(s.materials[0].diffuse, glm::vec3(0.8f)));
  const rvr::Material& zeta = s.materials[1];
  EXPECT_EQ(zeta.name, "zeta");
  EXPECT_TRUE(near3(zeta.diffuse, {0.1f, 0.2f, 0.3f}));
  EXPECT_TRUE(near3(zeta.specular, {0.4f, 0.5f, 0.6f}));
  EXPECT_TRUE(near3(zeta.emission, {1, 2, 3}));
  EXPECT_FLOAT_EQ(zeta.shininess, 50.0f);
  EXPECT_FLOAT_EQ(zeta.mirror, 0.25f);
  EXPECT_FLOAT_EQ(zeta.transparency, 0.5f);
  EXPECT_FLOAT_EQ(zeta.ior, 1.33f);
  const rvr::Material& alpha = s.materials[2];  // all defaults
  EXPECT_EQ(alpha.name, "alpha");
  EXPECT_TRUE(near3(alpha.diffuse, glm::vec3(0.8f)));
  EXPECT_TRUE(near3(alpha.specular, glm::vec3(0.0f)));
  EXPECT_TRUE(near3(alpha.emission, glm::vec3(0.0f)));
  EXPECT_FLOAT_EQ(alpha.shininess, 32.0f);
  EXPECT_FLOAT_EQ(alpha.mirror, 0.0f);
  EXPECT_FLOAT_EQ(alpha.transparency, 0.0f);
  EXPECT_FLOAT_EQ(alpha.ior, 1.0f);

  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_EQ(s.lights[0].type, rvr::LightType::Point);
  EXPECT_TRUE(near3(s.lights[0].position, {1, 2, 3}));
  EXPECT_TRUE(near3(s.lights[0].intensity, {4, 5, 6}));
  EXPECT_EQ(s.lights[1].type, rvr::LightType::Area);
  EXPECT_TRUE(near3(s.lights[1].corner, {-1, 4, -1}));
  EXPECT_TRUE(near3(s.lights[1].edge_u, {2, 0, 0}));
  EXPECT_TRUE(near3(s.lights[1].edge_v, {0, 0, 2}));
  EXPECT_TRUE(near3(s.lights[1].intensity, {8, 8, 8}));
  EXPECT_EQ(s.lights[1].samples, 3);
  EXPECT_EQ(s.lights[2].samples, 4);  // default

  ASSERT_EQ(s.objects.size(), 6u);
  const rvr::Object& ball = s.objects[0];
  EXPECT_EQ(ball.name, "ball");
  EXPECT_EQ(ball.type, rvr::ObjectType::Sphere);
  EXPECT_EQ(ball.material, 1u);
  EXPECT_TRUE(near3(ball.sphere.center, {0, 1, 0}));
  EXPECT_FLOAT_EQ(ball.sphere.radius, 1.0f);

  const rvr::Object& floor = s.objects[1];
  EXPECT_EQ(floor.name, "plane#1");
  EXPECT_EQ(floor.type, rvr::ObjectType::Plane);
  EXPECT_EQ(floor.material, 0u);                      // no material: the built-in grey
  EXPECT_TRUE(near3(floor.plane.normal, {0, 1, 0}));  // normalised
  EXPECT_FLOAT_EQ(floor.plane.half_size, 10.0f);      // default
  EXPECT_FLOAT_EQ(s.objects[2].plane.half_size, 3.0f);
  EXPECT_EQ(s.objects[2].material, 2u);

  const rvr::Object& tri = s.objects[3];
  EXPECT_EQ(tri.name, "triangle#3");
  EXPECT_EQ(tri.type, rvr::ObjectType::Triangles);
  ASSERT_EQ(tri.mesh.triangle_count(), 1u);
  EXPECT_TRUE(tri.mesh.normals.empty());
  EXPECT_TRUE(near3(tri.mesh.positions[tri.mesh.triangles[0].y], {1, 0, 0}));

  // scale 2, rotate 90 degrees about z, translate (1, 2, 3):
  // (1, 0, 0) -> (2, 0, 0) -> (0, 2, 0) -> (1, 4, 3); the normal (0, 1, 0) -> (-1, 0, 0).
  const rvr::Object& quad = s.objects[4];
  EXPECT_EQ(quad.name, "quad");
  EXPECT_EQ(quad.type, rvr::ObjectType::Triangles);
  EXPECT_EQ(quad.mesh.triangle_count(), 2u);
  EXPECT_TRUE(has_position(quad.mesh, {1, 4, 3}));
  EXPECT_TRUE(has_position(quad.mesh, {1, 2, 3}));  // the origin, translated
  EXPECT_TRUE(has_position(quad.mesh, {1, 4, 5}));  // (1, 0, 1)
  ASSERT_EQ(quad.mesh.normals.size(), quad.mesh.positions.size());
  for (const glm::vec3& n : quad.mesh.normals) EXPECT_TRUE(near3(n, {-1, 0, 0})) << n.x;

  const rvr::Object& csg = s.objects[5];
  EXPECT_EQ(csg.name, "csg#5");
  EXPECT_EQ(csg.type, rvr::ObjectType::Csg);
  ASSERT_TRUE(csg.csg);
  EXPECT_FALSE(csg.csg->is_leaf);
  EXPECT_EQ(csg.csg->op, rvr::CsgOp::Difference);
  ASSERT_TRUE(csg.csg->a && csg.csg->b);
  EXPECT_TRUE(csg.csg->a->is_leaf);
  EXPECT_FLOAT_EQ(csg.csg->a->sphere.radius, 1.0f);
  const rvr::CsgNode& inner = *csg.csg->b;
  EXPECT_FALSE(inner.is_leaf);
  EXPECT_EQ(inner.op, rvr::CsgOp::Intersection);
  EXPECT_TRUE(inner.a->is_leaf && inner.b->is_leaf);
  EXPECT_TRUE(near3(inner.a->sphere.center, {0.5f, 1.5f, 0.5f}));
  EXPECT_FLOAT_EQ(inner.b->sphere.radius, 0.5f);
  EXPECT_EQ(s.triangle_count(), 3u);
}

TEST_F(SceneLoader, DefaultsOfAMinimalScene) {
  Scene s = parse_ok(R"({"camera": {"eye": [3, 4, 0], "target": [0, 0, 0], "up": [0, 3, 0]}})");
  EXPECT_EQ(s.image.width, 640);
  EXPECT_EQ(s.image.height, 480);
  EXPECT_TRUE(near3(s.image.background, glm::vec3(0.0f)));
  EXPECT_EQ(s.image.samples_per_pixel, 1);
  EXPECT_FLOAT_EQ(s.camera.fov_y_deg, 45.0f);
  EXPECT_FLOAT_EQ(s.camera.near, 0.01f);
  EXPECT_FLOAT_EQ(s.camera.far, 1000.0f);
  EXPECT_FLOAT_EQ(s.camera.aperture_radius, 0.0f);
  EXPECT_FLOAT_EQ(s.camera.focus_distance, 5.0f);  // distance(eye, target)
  EXPECT_TRUE(near3(s.camera.up, {0, 1, 0}));      // only its direction matters
  EXPECT_TRUE(near3(s.ambient, glm::vec3(0.0f)));
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_TRUE(s.lights.empty());
  EXPECT_TRUE(s.objects.empty());
}

TEST_F(SceneLoader, IntegralFloatsAreAcceptedAsIntegers) {
  Scene s = parse_ok(scene(R"("image": {"width": 64.0, "height": 48})"));
  EXPECT_EQ(s.image.width, 64);
}

TEST_F(SceneLoader, TransformOnAnalyticShapes) {
  Scene s = parse_ok(scene(R"("objects": [
    {"type": "sphere", "center": [1, 0, 0], "radius": 0.5,
     "transform": {"scale": 2, "rotate_deg": [0, 90, 0], "translate": [0, 1, 0]}},
    {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "half_size": 2,
     "transform": {"scale": [-3, 3, 3], "rotate_deg": [90, 0, 0], "translate": [0, 0, -1]}},
    {"type": "csg", "op": "union", "transform": {"translate": [10, 0, 0]},
     "a": {"center": [0, 0, 0], "radius": 1}, "b": {"center": [1, 0, 0], "radius": 1}}
  ])"));
  ASSERT_EQ(s.objects.size(), 3u);
  // (1,0,0) * 2 = (2,0,0); rotated 90 degrees about y -> (0,0,-2); + (0,1,0).
  EXPECT_TRUE(near3(s.objects[0].sphere.center, {0, 1, -2}));
  EXPECT_FLOAT_EQ(s.objects[0].sphere.radius, 1.0f);
  // The normal (0,1,0) rotated 90 degrees about x is (0,0,1).
  EXPECT_TRUE(near3(s.objects[1].plane.point, {0, 0, -1}));
  EXPECT_TRUE(near3(s.objects[1].plane.normal, {0, 0, 1}));
  EXPECT_FLOAT_EQ(s.objects[1].plane.half_size, 6.0f);
  EXPECT_TRUE(near3(s.objects[2].csg->a->sphere.center, {10, 0, 0}));
  EXPECT_TRUE(near3(s.objects[2].csg->b->sphere.center, {11, 0, 0}));
}

TEST_F(SceneLoader, DiscIsReadTransformedAndNormalised) {
  Scene s = parse_ok(scene(R"("objects": [
    {"type": "disc", "center": [0, 0, 0], "normal": [0, 0, 3], "radius": 0.5},
    {"type": "disc", "name": "lid", "center": [1, 0, 0], "normal": [0, 1, 0], "radius": 0.25,
     "transform": {"scale": [-2, 2, 2], "rotate_deg": [90, 0, 0], "translate": [0, 0, 5]}}
  ])"));
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.objects[0].type, rvr::ObjectType::Disc);
  EXPECT_EQ(s.objects[0].name, "disc#0");
  EXPECT_TRUE(near3(s.objects[0].disc.normal, {0, 0, 1}));  // normalised
  EXPECT_FLOAT_EQ(s.objects[0].disc.radius, 0.5f);
  // (1,0,0) scaled by (-2,2,2) is (-2,0,0), which a rotation about x keeps, then + (0,0,5); the
  // normal (0,1,0) rotated 90 degrees about x is (0,0,1); the radius doubles.
  EXPECT_EQ(s.objects[1].name, "lid");
  EXPECT_TRUE(near3(s.objects[1].disc.center, {-2, 0, 5}));
  EXPECT_TRUE(near3(s.objects[1].disc.normal, {0, 0, 1}));
  EXPECT_FLOAT_EQ(s.objects[1].disc.radius, 0.5f);
}

TEST_F(SceneLoader, TransformOnTriangleAndNonUniformNormals) {
  // A smooth mesh with the normal (1,1,0)/sqrt2 on every vertex, scaled by (2,1,1): normals
  // go through the inverse transpose, (0.5, 1, 0), renormalised.
  write_file(dir_ / "slope.obj", "v 0 0 0\nv 1 -1 0\nv 0 0 1\nvn 1 1 0\nf 1//1 2//1 3//1\n");
  Scene s = parse_ok(scene(R"("objects": [
    {"type": "mesh", "file": "slope.obj", "smooth": true, "transform": {"scale": [2, 1, 1]}},
    {"type": "triangle", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
     "transform": {"translate": [0, 0, 5]}}
  ])"));
  ASSERT_EQ(s.objects.size(), 2u);
  glm::vec3 expected = glm::normalize(glm::vec3(0.5f, 1.0f, 0.0f));
  ASSERT_FALSE(s.objects[0].mesh.normals.empty());
  for (const glm::vec3& n : s.objects[0].mesh.normals) EXPECT_TRUE(near3(n, expected));
  EXPECT_TRUE(has_position(s.objects[0].mesh, {2, -1, 0}));
  EXPECT_TRUE(has_position(s.objects[1].mesh, {0, 1, 5}));
}

TEST_F(SceneLoader, LoadSceneFileResolvesMeshesBesideTheScene) {
  write_file(dir_ / "sub" / "models" / "quad.obj", kQuadObj);
  write_file(dir_ / "sub" / "scene.json",
             one_object(R"({"type": "mesh", "file": "models/quad.obj"})"));
  Expected<Scene> s = rvr::load_scene((dir_ / "sub" / "scene.json").string());
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->source, (dir_ / "sub" / "scene.json").string());
  EXPECT_EQ(s->objects[0].mesh.triangle_count(), 2u);
  EXPECT_TRUE(s->objects[0].mesh.normals.empty());  // flat
}

TEST_F(SceneLoader, LoadSceneFileErrors) {
  std::string missing = (dir_ / "nope.json").string();
  Expected<Scene> s = rvr::load_scene_file(missing);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message, missing + ": cannot read: No such file or directory");
  EXPECT_EQ(s.error().kind, rvr::ErrorKind::BadInput);

  Expected<Scene> d = rvr::load_scene_file(dir_.string());
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().message, dir_.string() + ": cannot read: Is a directory");

  // Errors inside the file name the path as given.
  write_file(dir_ / "bad.json",
             one_object(R"({"type": "sphere", "center": [0,0,0], "radius": -1})"));
  Expected<Scene> b = rvr::load_scene((dir_ / "bad.json").string());
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.error().message,
            (dir_ / "bad.json").string() + ": objects[0].radius: must be > 0, got -1");
}

TEST_F(SceneLoader, BuiltinSpecsGoToTheBuiltinScenes) {
  Expected<Scene> s = rvr::load_scene("builtin:cornell");
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_FALSE(s->objects.empty());
  EXPECT_EQ(s->source, "builtin:cornell");
  Expected<Scene> bad = rvr::load_scene("builtin:no-such-scene");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("no-such-scene"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// Bad input: one row per mistake, with the exact message (or its distinctive part).

struct BadCase {
  const char* label;
  std::string text;
  std::string expected;  // a substring of the message, which always starts with "t.json"
};

std::vector<BadCase> bad_cases() {
  auto sphere = [](const std::string& extra) {
    return one_object(R"({"type": "sphere", "center": [0, 0, 0], )" + extra + "}");
  };
  auto material = [](const std::string& body) {
    return scene(R"("materials": {"m": {)" + body + "}}");
  };
  auto camera = [](const std::string& body) { return "{\"camera\": {" + body + "}}"; };
  const std::string eye_target = R"("eye": [0, 1, 4], "target": [0, 1, 0], )";
  auto light = [](const std::string& body) { return scene("\"lights\": [" + body + "]"); };
  std::string deep_csg = R"({"center": [0, 0, 0], "radius": 1})";
  for (int i = 0; i < 70; ++i) {
    deep_csg =
        R"({"op": "union", "a": )" + deep_csg + R"(, "b": {"center": [0,0,0], "radius": 1}})";
  }
  return {
      // JSON syntax, with line:column of the offending token
      {"missing comma", "{\n  \"camera\": {}\n  \"objects\": []\n}",
       "t.json:3:3: JSON syntax: expected ',' or '}', got a string"},
      {"missing comma in array", R"({"objects": [1 2]})",
       "t.json:1:16: JSON syntax: expected ',' or ']', got a number"},
      {"trailing comma", R"({"objects": [1,]})",
       "t.json:1:16: JSON syntax: expected a value, got ']' (trailing comma?)"},
      {"truncated", "{\"camera\": ", "t.json:1:12: JSON syntax: unexpected end of input"},
      {"bad literal", "{\"camera\": tru}", "t.json:1:15: JSON syntax: invalid literal"},
      {"text after the value", "{} x", "t.json:1:4: JSON syntax: unexpected text after the end"},
      {"column counts characters", "{\"caméra\": 1 2}",
       "t.json:1:14: JSON syntax: expected ',' or '}', got a number"},
      {"empty file", "", "t.json:1:1: JSON syntax: unexpected end of input (the file is empty)"},
      {"blank file", "  \n ", "JSON syntax: unexpected end of input (the file is empty)"},
      {"too deep JSON", std::string(600, '['),
       "t.json:1:513: JSON syntax: nesting deeper than 512"},
      // structure and keys
      {"non-object root", "[1, 2]", "t.json: top level: must be an object, got array of 2"},
      {"wrong format", scene(R"("format": "rvr-scene/2")"),
       "t.json: format: must be 'rvr-scene/1', got 'rvr-scene/2'"},
      {"format not a string", scene(R"("format": 1)"),
       "t.json: format: must be a string, got number 1"},
      {"missing camera", R"({"objects": []})", "t.json: camera: is required"},
      {"unknown top-level key", scene(R"("camra": {})"),
       "t.json: top level: unknown key 'camra' (did you mean 'camera'?)"},
      {"unknown camera key", camera(eye_target + R"("up": [0,1,0], "fov_y_dg": 40)"),
       "t.json: camera: unknown key 'fov_y_dg' (did you mean 'fov_y_deg'?)"},
      {"unknown image key", scene(R"("image": {"widht": 10})"),
       "t.json: image: unknown key 'widht' (did you mean 'width'?)"},
      {"unknown object key", sphere(R"("radus": 1)"),
       "t.json: objects[0]: unknown key 'radus' for a sphere (did you mean 'radius'?)"},
      {"key of another object type", one_object(R"({"type": "plane", "point": [0,0,0],
           "normal": [0,1,0], "radius": 1})"),
       "t.json: objects[0]: unknown key 'radius' for a plane; allowed: half_size, material, name"},
      {"unknown material key", material(R"("difuse": [1, 1, 1])"),
       "t.json: materials.m: unknown key 'difuse' (did you mean 'diffuse'?)"},
      {"unknown light key", light(R"({"type": "point", "positon": [0,0,0], "intensity": [1,1,1]})"),
       "t.json: lights[0]: unknown key 'positon' for a point light (did you mean 'position'?)"},
      {"unknown transform key", sphere(R"("radius": 1, "transform": {"spin": [0, 1, 0]})"),
       "t.json: objects[0].transform: unknown key 'spin'; allowed: rotate_deg, scale, translate"},
      {"duplicate key", sphere(R"("radius": 1, "radius": 2)"),
       "t.json: objects[0].radius: duplicate key"},
      {"objects not an array", scene(R"("objects": {})"),
       "t.json: objects: must be an array, got object"},
      {"object not an object", scene(R"("objects": [3])"),
       "t.json: objects[0]: must be an object, got number 3"},
      // types and numbers
      {"string for a number", sphere(R"("radius": "1")"),
       "t.json: objects[0].radius: must be a number, got string '1'"},
      {"short vector", camera(R"("eye": [0, 1], "target": [0, 0, 0], "up": [0, 1, 0])"),
       "t.json: camera.eye: must be an array of 3 numbers, got array of 2"},
      {"vector element type",
       camera(R"("eye": [0, null, 1], "target": [0, 0, 0], "up": [0, 1, 0])"),
       "t.json: camera.eye[1]: must be a number, got null"},
      {"overflowing number", sphere(R"("radius": 1e999)"),
       "t.json: objects[0].radius: must be a finite number, got 1e999"},
      {"overflowing negative number", scene(R"("ambient": [0, -1e400, 0])"),
       "t.json: ambient[1]: must be a finite number, got -1e400"},
      {"beyond float range", sphere(R"("radius": 1e300)"),
       "t.json: objects[0].radius: is out of range for a 32-bit float, got 1e+300"},
      {"bool for a boolean", one_object(R"({"type": "mesh", "file": "x.obj", "smooth": 1})"),
       "t.json: objects[0].smooth: must be true or false, got number 1"},
      {"name not a string", sphere(R"("radius": 1, "name": 7)"),
       "t.json: objects[0].name: must be a string, got number 7"},
      // ranges
      {"negative radius", sphere(R"("radius": -1)"),
       "t.json: objects[0].radius: must be > 0, got -1"},
      {"zero width", scene(R"("image": {"width": 0})"),
       "t.json: image.width: must be an integer in 1..16384, got number 0"},
      {"huge height", scene(R"("image": {"height": 100000})"),
       "t.json: image.height: must be an integer in 1..16384, got number 100000"},
      {"fractional width", scene(R"("image": {"width": 640.5})"),
       "t.json: image.width: must be an integer in 1..16384, got number 640.5"},
      {"zero spp", scene(R"("image": {"samples_per_pixel": 0})"),
       "t.json: image.samples_per_pixel: must be an integer in 1..4096"},
      {"negative background", scene(R"("image": {"background": [0, 0, -0.5]})"),
       "t.json: image.background[2]: must be >= 0 (colours are non-negative), got -0.5"},
      {"fov 180", camera(eye_target + R"("up": [0, 1, 0], "fov_y_deg": 180)"),
       "t.json: camera.fov_y_deg: must be in (0, 180), got 180"},
      {"near 0", camera(eye_target + R"("up": [0, 1, 0], "near": 0)"),
       "t.json: camera.near: must be > 0, got 0"},
      {"far below near", camera(eye_target + R"("up": [0, 1, 0], "near": 1, "far": 0.5)"),
       "t.json: camera.far: must be > camera.near (1), got 0.5"},
      {"negative aperture", camera(eye_target + R"("up": [0, 1, 0], "aperture_radius": -0.1)"),
       "t.json: camera.aperture_radius: must be >= 0, got -0.1"},
      {"zero focus distance", camera(eye_target + R"("up": [0, 1, 0], "focus_distance": 0)"),
       "t.json: camera.focus_distance: must be > 0, got 0"},
      {"parallel up", camera(eye_target + R"("up": [0, 0, -2])"),
       "t.json: camera.up: must not be parallel to target - eye"},
      {"zero up", camera(eye_target + R"("up": [0, 0, 0])"), "t.json: camera.up: must be non-zero"},
      {"eye equals target", camera(R"("eye": [1, 2, 3], "target": [1, 2, 3], "up": [0, 1, 0])"),
       "t.json: camera.target: must differ from camera.eye (both are [1, 2, 3])"},
      {"eye too close to target",
       camera(R"("eye": [0, 0, 0], "target": [1e-30, 0, 0], "up": [0, 1, 0])"),
       "t.json: camera.target: is too far from or too close to camera.eye for 32-bit floats"},
      {"missing up", camera(eye_target.substr(0, eye_target.size() - 2)),
       "t.json: camera.up: is required"},
      {"negative shininess", material(R"("shininess": -1)"),
       "t.json: materials.m.shininess: must be >= 0, got -1"},
      {"mirror above 1", material(R"("mirror": 1.5)"),
       "t.json: materials.m.mirror: must be in 0..1, got 1.5"},
      {"mirror plus transparency", material(R"("mirror": 0.6, "transparency": 0.5)"),
       "t.json: materials.m: mirror + transparency must be <= 1, got 0.6 + 0.5"},
      {"ior below 1", material(R"("ior": 0.9)"), "t.json: materials.m.ior: must be >= 1, got 0.9"},
      {"material not an object", scene(R"("materials": {"m": [1]})"),
       "t.json: materials.m: must be an object, got array of 1"},
      {"odd material name", scene(R"("materials": {"my glass": {"ior": 0}})"),
       "t.json: materials['my glass'].ior: must be >= 1, got 0"},
      // references
      {"missing material", sphere(R"("radius": 1, "material": "steel")"),
       "t.json: objects[0].material: unknown material 'steel'"},
      {"material typo", scene(R"("materials": {"white": {}}, "objects": [{"type": "sphere",
           "center": [0,0,0], "radius": 1, "material": "whte"}])"),
       "t.json: objects[0].material: unknown material 'whte' (did you mean 'white'?)"},
      // lights
      {"light type", light(R"({"type": "spot", "position": [0,0,0]})"),
       "t.json: lights[0].type: unknown light type 'spot'"},
      {"light without type", light(R"({"position": [0,0,0]})"),
       "t.json: lights[0].type: is required"},
      {"point light without intensity", light(R"({"type": "point", "position": [0,0,0]})"),
       "t.json: lights[0].intensity: is required"},
      {"samples on a point light",
       light(R"({"type": "point", "position": [0,0,0], "intensity": [1,1,1], "samples": 2})"),
       "t.json: lights[0]: unknown key 'samples' for a point light"},
      {"zero-area light", light(R"({"type": "point", "position": [0,0,0], "intensity": [1,1,1]},
                {"type": "area", "corner": [0,4,0], "edge_u": [1,0,0], "edge_v": [-2,0,0],
                 "intensity": [1,1,1]})"),
       "t.json: lights[1].edge_v: is parallel to edge_u (the light would have zero area)"},
      {"zero light edge",
       light(R"({"type": "area", "corner": [0,4,0], "edge_u": [0,0,0], "edge_v": [1,0,0],
                 "intensity": [1,1,1]})"),
       "t.json: lights[0].edge_u: must be non-zero"},
      {"too many light samples",
       light(R"({"type": "area", "corner": [0,4,0], "edge_u": [1,0,0], "edge_v": [0,0,1],
                 "intensity": [1,1,1], "samples": 100})"),
       "t.json: lights[0].samples: must be an integer in 1..64 (samples per side, capped at 64), "
       "got number 100"},
      // objects
      {"object without type", one_object(R"({"center": [0,0,0]})"),
       "t.json: objects[0].type: is required"},
      {"object type typo", one_object(R"({"type": "sphre"})"),
       "t.json: objects[0].type: unknown object type 'sphre' (did you mean 'sphere'?)"},
      {"sphere without radius", one_object(R"({"type": "sphere", "center": [0,0,0]})"),
       "t.json: objects[0].radius: is required"},
      {"zero plane normal", one_object(R"({"type": "plane", "point": [0,0,0], "normal": [0,0,0]})"),
       "t.json: objects[0].normal: must be non-zero"},
      {"disc without radius",
       one_object(R"({"type": "disc", "center": [0,0,0], "normal": [0,1,0]})"),
       "t.json: objects[0].radius: is required"},
      {"zero disc radius",
       one_object(R"({"type": "disc", "center": [0,0,0], "normal": [0,1,0], "radius": 0})"),
       "t.json: objects[0].radius: must be > 0, got 0"},
      {"zero disc normal",
       one_object(R"({"type": "disc", "center": [0,0,0], "normal": [0,0,0], "radius": 1})"),
       "t.json: objects[0].normal: must be non-zero"},
      {"a plane's key on a disc",
       one_object(R"({"type": "disc", "center": [0,0,0], "normal": [0,1,0], "radius": 1,
                      "half_size": 2})"),
       "t.json: objects[0]: unknown key 'half_size' for a disc; allowed: center, material, name, "
       "normal, radius, transform, type"},
      {"non-uniform scale on a disc",
       one_object(R"({"type": "disc", "center": [0,0,0], "normal": [0,1,0], "radius": 1,
                      "transform": {"scale": [1, 2, 1]}})"),
       "t.json: objects[0].transform.scale: a disc needs a uniform scale (one number, or three of "
       "equal magnitude), got [1, 2, 1]"},
      {"zero half size",
       one_object(R"({"type": "plane", "point": [0,0,0], "normal": [0,1,0], "half_size": 0})"),
       "t.json: objects[0].half_size: must be > 0, got 0"},
      {"two vertices", one_object(R"({"type": "triangle", "vertices": [[0,0,0], [1,0,0]]})"),
       "t.json: objects[0].vertices: must be an array of 3 vertices, got array of 2"},
      {"degenerate triangle",
       one_object(R"({"type": "triangle", "vertices": [[0,0,0], [1,1,1], [2,2,2]]})"),
       "t.json: objects[0].vertices: the triangle is degenerate (zero area)"},
      {"non-uniform scale on a sphere", sphere(R"("radius": 1, "transform": {"scale": [1, 2, 1]})"),
       "t.json: objects[0].transform.scale: a sphere needs a uniform scale"},
      {"zero scale", sphere(R"("radius": 1, "transform": {"scale": 0})"),
       "t.json: objects[0].transform.scale: must be non-zero, got 0"},
      // meshes
      {"missing mesh file", one_object(R"({"type": "mesh", "file": "models/nope.obj"})"),
       "t.json: objects[0].file: cannot read 'models/nope.obj': No such file or directory"},
      {"garbage mesh file", one_object(R"({"type": "mesh", "file": "garbage.ply"})"),
       "t.json: objects[0].file: cannot read 'garbage.ply': "},
      {"mesh without faces", one_object(R"({"type": "mesh", "file": "points.obj"})"),
       "t.json: objects[0].file: "},
      {"mesh without triangles file", one_object(R"({"type": "mesh"})"),
       "t.json: objects[0].file: is required"},
      {"mesh of degenerate triangles", one_object(R"({"type": "mesh", "file": "flat.obj"})"),
       "t.json: objects[0].file: 'flat.obj': all 2 triangles are degenerate (zero area)"},
      {"non-finite mesh vertex", one_object(R"({"type": "mesh", "file": "inf.obj"})"),
       "t.json: objects[0].file: 'inf.obj': vertex 0 of mesh 0 has a non-finite coordinate"},
      {"NUL in a mesh path", one_object(R"({"type": "mesh", "file": "a\u0000b.obj"})"),
       "t.json: objects[0].file: must not contain a NUL character"},
      {"mesh file is a folder", one_object(R"({"type": "mesh", "file": "."})"),
       "t.json: objects[0].file: cannot read '.': Is a directory"},
      // csg
      {"bad csg op",
       one_object(R"({"type": "csg", "op": "subtract", "a": {"center": [0,0,0], "radius": 1},
                      "b": {"center": [0,0,0], "radius": 1}})"),
       "t.json: objects[0].op: unknown csg op 'subtract'"},
      {"csg without b", one_object(R"({"type": "csg", "op": "union",
                                        "a": {"center": [0,0,0], "radius": 1}})"),
       "t.json: objects[0].b: is required"},
      {"material inside csg", one_object(R"({"type": "csg", "op": "union",
                      "a": {"center": [0,0,0], "radius": 1, "material": "m"},
                      "b": {"center": [0,0,0], "radius": 1}})"),
       "t.json: objects[0].a: 'material' is not allowed inside a csg tree"},
      {"unknown key inside csg",
       one_object(R"({"type": "csg", "op": "union", "a": {"center": [0,0,0], "radius": 1},
                      "b": {"center": [0,0,0], "radious": 1}})"),
       "t.json: objects[0].b: unknown key 'radious' for a csg sphere (did you mean 'radius'?)"},
      {"plane inside csg", one_object(R"({"type": "csg", "op": "union", "a": {"type": "plane"},
                      "b": {"center": [0,0,0], "radius": 1}})"),
       "t.json: objects[0].a.type: must be 'sphere' or 'csg' inside a csg tree, got 'plane'"},
      {"bad radius deep in csg",
       one_object(R"({"type": "csg", "op": "union", "a": {"center": [0,0,0], "radius": 1},
                      "b": {"op": "difference", "a": {"center": [0,0,0], "radius": 1},
                            "b": {"center": [0,0,0], "radius": 0}}})"),
       "t.json: objects[0].b.b.radius: must be > 0, got 0"},
      {"deep csg", one_object(R"({"type": "csg", )" + deep_csg.substr(1)),
       "csg tree nested deeper than 64 levels"},
      // Textures, texture coordinates and vertex colours.
      {"texture not a string", material(R"("texture": 3)"),
       "t.json: materials.m.texture: must be an image file name or an object with \"file\", got "
       "number 3"},
      {"texture empty", material(R"("texture": "")"),
       "t.json: materials.m.texture: must not be empty"},
      {"texture without file", material(R"("texture": {"wrap": "clamp"})"),
       "t.json: materials.m.texture.file: is required (the image file)"},
      {"texture unknown key", material(R"("texture": {"file": "a.png", "wrapp": "clamp"})"),
       "t.json: materials.m.texture: unknown key 'wrapp' for a texture (did you mean 'wrap'?)"},
      {"unknown wrap", material(R"("texture": {"file": "a.png", "wrap": "clampp"})"),
       "t.json: materials.m.texture.wrap: unknown wrap mode 'clampp' (did you mean 'clamp'?)"},
      {"wrap of three",
       material(R"("texture": {"file": "a.png", "wrap": ["clamp", "clamp", "clamp"]})"),
       "t.json: materials.m.texture.wrap: must be a wrap mode or an array of 2, got array of 3"},
      {"bad v wrap", material(R"("texture": {"file": "a.png", "wrap": ["clamp", 1]})"),
       "t.json: materials.m.texture.wrap[1]: must be a string"},
      {"transform scale 0",
       material(R"("texture": {"file": "a.png", "transform": {"scale": [1, 0]}})"),
       "t.json: materials.m.texture.transform.scale[1]: must not be 0"},
      {"transform offset of 3",
       material(R"("texture": {"file": "a.png", "transform": {"offset": [1, 0, 0]}})"),
       "t.json: materials.m.texture.transform.offset: must be an array of 2 numbers, got array of "
       "3"},
      {"transform rotation overflows",
       material(R"("texture": {"file": "a.png", "transform": {"rotation": 1e400}})"),
       "t.json: materials.m.texture.transform.rotation: must be a finite number"},
      {"triangle uvs of 2",
       one_object(R"({"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,0]],
                      "uvs": [[0,0],[1,0]]})"),
       "t.json: objects[0].uvs: must be an array of 3 (one per vertex), got array of 2"},
      {"triangle uv of 3 numbers",
       one_object(R"({"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,0]],
                      "uvs": [[0,0],[1,0,0],[0,1]]})"),
       "t.json: objects[0].uvs[1]: must be an array of 2 numbers, got array of 3"},
      {"triangle uv not finite",
       one_object(R"({"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,0]],
                      "uvs": [[0,0],[1,0],[0,1e999]]})"),
       "t.json: objects[0].uvs[2][1]: must be a finite number"},
      {"triangle colour negative",
       one_object(R"({"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,0]],
                      "colors": [[0,0,0],[1,0,-1],[0,1,0]]})"),
       "t.json: objects[0].colors[1][2]: must be >= 0"},
      {"mesh colours of the wrong count",
       one_object(R"({"type": "mesh", "file": "quad.obj", "colors": [[1,1,1]]})"),
       "t.json: objects[0].colors: must be an array of 4 (one per vertex of 'quad.obj' as "
       "loaded), got array of 1"},
      {"uvs with from_file",
       one_object(R"({"type": "mesh", "file": "quad.obj", "material": "from_file",
                      "uvs": []})"),
       "t.json: objects[0].uvs: is not allowed with \"material\": \"from_file\""},
  };
}

TEST_F(SceneLoader, BadInputsGiveExactMessages) {
  write_file(dir_ / "garbage.ply", std::string("\x01\x02garbage\xff\xfe not a ply file", 27));
  write_file(dir_ / "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  write_file(dir_ / "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n");
  write_file(dir_ / "inf.obj", "v 1e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write_file(dir_ / "quad.obj", kQuadObj);
  std::vector<BadCase> cases = bad_cases();
  EXPECT_GE(cases.size(), 30u);
  for (const BadCase& c : cases) {
    Expected<Scene> s = parse(c.text);
    if (s.ok()) {
      ADD_FAILURE() << c.label << ": loaded, expected error containing: " << c.expected;
      continue;
    }
    EXPECT_EQ(s.error().kind, rvr::ErrorKind::BadInput) << c.label;
    EXPECT_EQ(s.error().message.rfind("t.json", 0), 0u) << c.label << ": " << s.error().message;
    EXPECT_NE(s.error().message.find(c.expected), std::string::npos)
        << c.label << "\n  got:      " << s.error().message << "\n  expected: " << c.expected;
    EXPECT_EQ(s.error().message.find('\n'), std::string::npos) << c.label;
  }
}

// Textures (file or object, wrap modes, transform), uvs and colours on triangles and meshes;
// a texture file that is missing is a warning naming it and the material's path.
TEST_F(SceneLoader, TexturesUvsAndColours) {
  write_file(dir_ / "quad.obj", kQuadObj);
  rvr::Image image;
  image.width = 2;
  image.height = 1;
  image.channels = 3;
  image.pixels = {0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f};  // black, white: sRGB 0 and 1 are exact
  fs::create_directories(dir_ / "img");
  ASSERT_TRUE(rvr::write_image((dir_ / "img" / "bw.png").string(), image, false).ok());
  Scene s = parse_ok(scene(R"("materials": {
      "plain": {"texture": "img/bw.png"},
      "tiles": {"texture": {"file": "img/bw.png", "wrap": ["clamp", "mirror"],
                            "transform": {"offset": [0.5, 0.25], "rotation": 1.5, "scale": [2, 4]}}},
      "lost": {"texture": {"file": "nowhere.png", "wrap": "mirror"}}},
    "objects": [
      {"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,0]], "material": "tiles",
       "uvs": [[0, 0], [1, 0.5], [0.25, 1]], "colors": [[1, 0, 0], [0, 1, 0], [0, 0, 0.5]]},
      {"type": "mesh", "file": "quad.obj", "material": "plain",
       "uvs": [[0, 0], [1, 0], [1, 1], [0, 1]]},
      {"type": "mesh", "file": "quad.obj", "material": "lost"}])"));
  ASSERT_EQ(s.materials.size(), 4u);
  const rvr::Material &plain = s.materials[1], &tiles = s.materials[2], &lost = s.materials[3];
  // One image, two textures (their wrap modes differ), and the missing one.
  ASSERT_EQ(s.textures.size(), 3u);
  EXPECT_EQ(plain.texture, 0);
  EXPECT_EQ(tiles.texture, 1);
  EXPECT_EQ(lost.texture, 2);
  EXPECT_TRUE(plain.uv_transform.identity());
  EXPECT_EQ(tiles.uv_transform.offset, glm::vec2(0.5f, 0.25f));
  EXPECT_EQ(tiles.uv_transform.rotation, 1.5f);
  EXPECT_EQ(tiles.uv_transform.scale, glm::vec2(2.0f, 4.0f));
  EXPECT_EQ(s.textures[0].wrap_u, rvr::TextureWrap::Repeat);
  EXPECT_EQ(s.textures[0].wrap_v, rvr::TextureWrap::Repeat);
  EXPECT_EQ(s.textures[1].wrap_u, rvr::TextureWrap::ClampToEdge);
  EXPECT_EQ(s.textures[1].wrap_v, rvr::TextureWrap::MirroredRepeat);
  EXPECT_EQ(s.textures[2].wrap_u, rvr::TextureWrap::MirroredRepeat);
  ASSERT_TRUE(s.textures[0].mips);
  EXPECT_EQ(s.textures[0].mips, s.textures[1].mips);  // decoded once
  const rvr::TextureLevel& level = s.textures[0].mips->levels[0];
  ASSERT_EQ(level.width, 2);
  ASSERT_EQ(level.height, 1);
  EXPECT_EQ(level.at(0, 0), glm::vec3(0.0f));
  EXPECT_EQ(level.at(1, 0), glm::vec3(1.0f));
  EXPECT_FALSE(s.textures[2].mips);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], "materials.lost.texture: texture 'nowhere.png' not found (looked in '" +
                               dir_.string() + "', '" + dir_.parent_path().string() +
                               "' and their subfolders): rendered without it");

  const rvr::TriangleMesh& tri = s.objects[0].mesh;
  ASSERT_EQ(tri.uvs.size(), 3u);
  EXPECT_EQ(tri.uvs[1], glm::vec2(1.0f, 0.5f));
  EXPECT_EQ(tri.colours[2], glm::vec3(0.0f, 0.0f, 0.5f));
  // The quad's uvs follow its vertices as loaded: in the order the faces first use them
  // ("f 1 4 3", "f 1 3 2": OBJ vertices 1, 4, 3, 2).
  const rvr::TriangleMesh& quad = s.objects[1].mesh;
  ASSERT_EQ(quad.positions.size(), 4u);
  const glm::vec2 uvs[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const glm::vec3 obj_positions[4] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}};
  for (size_t v = 0; v < 4; ++v) {
    EXPECT_EQ(quad.positions[v], obj_positions[v]);
    EXPECT_EQ(quad.uvs[v], uvs[v]);
  }
  EXPECT_FALSE(s.objects[2].mesh.textured());
}

TEST_F(SceneLoader, DeepJsonInsideStringsIsNotNesting) {
  // Brackets inside strings do not count towards the nesting limit.
  Scene s = parse_ok(scene(R"("objects": [{"type": "sphere", "name": ")" + std::string(2000, '[') +
                           R"(", "center": [0,0,0], "radius": 1}])"));
  EXPECT_EQ(s.objects[0].name.size(), 2000u);
}

TEST_F(SceneLoader, HostileInputNeverThrows) {
  // Truncations of a valid scene at every length: all must fail cleanly or load.
  std::string text = one_object(
      R"({"type": "csg", "op": "union", "a": {"center": [0,0,0], "radius": 1},
          "b": {"center": [1,0,0], "radius": 1}})");
  for (size_t n = 0; n < text.size(); ++n) {
    Expected<Scene> s = parse(text.substr(0, n));
    EXPECT_FALSE(s.ok()) << n;
  }
  EXPECT_TRUE(parse(text).ok());
  EXPECT_FALSE(parse(std::string(100000, '{')).ok());
  EXPECT_FALSE(parse(std::string("{\"a\":\"\xff\"}")).ok());
}

// ---------------------------------------------------------------------------------------------
// Meshes in each format

TEST_F(SceneLoader, ObjFlatAndSmooth) {
  write_file(dir_ / "quad.obj", kQuadObj);
  Scene s = parse_ok(scene(R"("objects": [
    {"type": "mesh", "file": "quad.obj"},
    {"type": "mesh", "file": "quad.obj", "smooth": true}])"));
  const rvr::TriangleMesh& flat = s.objects[0].mesh;
  EXPECT_EQ(flat.triangle_count(), 2u);
  EXPECT_TRUE(flat.normals.empty());
  EXPECT_FALSE(flat.smooth());
  const rvr::TriangleMesh& smooth = s.objects[1].mesh;
  EXPECT_EQ(smooth.triangle_count(), 2u);
  ASSERT_EQ(smooth.normals.size(), smooth.positions.size());  // generated: the file has none
  for (const glm::vec3& n : smooth.normals) EXPECT_TRUE(near3(glm::abs(n), {0, 1, 0}));
  EXPECT_TRUE(s.warnings.empty());
}

TEST_F(SceneLoader, PlyWithDegenerateTrianglesDropsThemWithAWarning) {
  write_file(dir_ / "degen.ply",
             "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
             "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n2 0 0\n1 1 0\n"
             "3 0 1 2\n3 0 0 1\n3 0 1 3\n3 1 4 2\n");
  Scene s = parse_ok(one_object(R"({"name": "bunny", "type": "mesh", "file": "degen.ply"})"));
  EXPECT_EQ(s.objects[0].mesh.triangle_count(), 2u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], "objects[0] (bunny): dropped 2 degenerate triangles");
}

TEST_F(SceneLoader, BinaryPly) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 2, 0};
  ply.append(reinterpret_cast<const char*>(v), sizeof v);
  const unsigned char n = 3;
  const int32_t idx[3] = {0, 1, 2};
  ply.append(reinterpret_cast<const char*>(&n), 1);
  ply.append(reinterpret_cast<const char*>(idx), sizeof idx);
  write_file(dir_ / "tri.ply", ply);
  Scene s = parse_ok(one_object(R"({"type": "mesh", "file": "tri.ply", "smooth": true})"));
  EXPECT_EQ(s.objects[0].mesh.triangle_count(), 1u);
  EXPECT_TRUE(has_position(s.objects[0].mesh, {0, 2, 0}));
  for (const glm::vec3& nn : s.objects[0].mesh.normals) EXPECT_TRUE(near3(glm::abs(nn), {0, 0, 1}));
}

TEST_F(SceneLoader, GltfWithEmbeddedBufferAppliesNodeTransforms) {
  // One triangle (0,0,0) (1,0,0) (0,1,0) in a node translated by (5,0,0) and scaled by 2.
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string bytes(reinterpret_cast<const char*>(pos), sizeof pos);
  static const char* kB64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t w = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) w |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) w |= uint32_t(uint8_t(bytes[i + 2]));
    b64 += kB64[(w >> 18) & 63];
    b64 += kB64[(w >> 12) & 63];
    b64 += i + 1 < bytes.size() ? kB64[(w >> 6) & 63] : '=';
    b64 += i + 2 < bytes.size() ? kB64[w & 63] : '=';
  }
  write_file(dir_ / "tri.gltf", R"({"asset": {"version": "2.0"}, "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0, "translation": [5, 0, 0], "scale": [2, 2, 2]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,)" +
                                    b64 + R"("}]})");
  Scene s = parse_ok(one_object(R"({"type": "mesh", "file": "tri.gltf",
                                    "transform": {"translate": [0, 0, 1]}})"));
  const rvr::TriangleMesh& m = s.objects[0].mesh;
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_TRUE(has_position(m, {5, 0, 1}));
  EXPECT_TRUE(has_position(m, {7, 0, 1}));
  EXPECT_TRUE(has_position(m, {5, 2, 1}));
}

TEST_F(SceneLoader, ShippedModelsInEveryFormat) {
  const fs::path models = fs::path(RVR_SOURCE_DIR) / "scenes" / "models";
  struct Model {
    const char* file;
    size_t triangles;
  };
  for (const Model& m : {Model{"torus.obj", 2304}, Model{"blob.ply", 5120},
                         Model{"vase.gltf", 1568}, Model{"crystal.3ds", 140}}) {
    for (bool smooth : {false, true}) {
      std::string text =
          one_object(std::string(R"({"type": "mesh", "file": ")") + (models / m.file).string() +
                     R"(", "smooth": )" + (smooth ? "true" : "false") + "}");
      Expected<Scene> s = parse(text);
      ASSERT_TRUE(s.ok()) << m.file << ": " << s.error().message;
      const rvr::TriangleMesh& mesh = s->objects[0].mesh;
      EXPECT_EQ(mesh.triangle_count(), m.triangles) << m.file;
      EXPECT_TRUE(s->warnings.empty()) << m.file << ": " << s->warnings[0];
      EXPECT_EQ(mesh.smooth(), smooth) << m.file;
      // Every model stands on y = 0 and is about a unit across (the vase's glTF node scales
      // it to 1.2 high: node transforms are applied).
      glm::vec3 lo(1e30f), hi(-1e30f);
      for (const glm::vec3& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
      EXPECT_NEAR(lo.y, 0.0f, 1e-4f) << m.file;
      EXPECT_GT(hi.y, 0.3f) << m.file;
      EXPECT_LT(hi.y, 1.3f) << m.file;
      for (const glm::vec3& n : mesh.normals) {
        ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f) << m.file;
      }
    }
  }
  Expected<Scene> vase = parse(
      one_object(R"({"type": "mesh", "file": ")" + (models / "vase.gltf").string() + R"("})"));
  ASSERT_TRUE(vase.ok());
  float top = 0;
  for (const glm::vec3& p : vase->objects[0].mesh.positions) top = std::max(top, p.y);
  EXPECT_NEAR(top, 1.2f, 1e-4f);
}

TEST_F(SceneLoader, BadVertexNormalsAreReplacedByFaceNormals) {
  write_file(dir_ / "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n");
  Scene s = parse_ok(one_object(R"({"type": "mesh", "file": "zero.obj", "smooth": true})"));
  const rvr::TriangleMesh& m = s.objects[0].mesh;
  ASSERT_EQ(m.normals.size(), 3u);
  for (const glm::vec3& n : m.normals) EXPECT_TRUE(near3(n, {0, 0, 1}));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("replaced 3 zero or non-finite vertex normals"), std::string::npos);
}

TEST_F(SceneLoader, ThreeDsWrittenByTheTest) {
  // A minimal 3DS file: main chunk > editor > object "tri" > triangle mesh > vertices, faces.
  auto chunk = [](uint16_t id, const std::string& payload) {
    std::string c(6, '\0');
    uint32_t len = uint32_t(6 + payload.size());
    std::memcpy(&c[0], &id, 2);
    std::memcpy(&c[2], &len, 4);
    return c + payload;
  };
  std::string verts(2, '\0');
  uint16_t nv = 3;
  std::memcpy(&verts[0], &nv, 2);
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 0, 1};  // z-up: (0,0,1) becomes (0,1,0)
  verts.append(reinterpret_cast<const char*>(v), sizeof v);
  std::string faces(2, '\0');
  uint16_t nf = 1;
  std::memcpy(&faces[0], &nf, 2);
  const uint16_t f[4] = {0, 1, 2, 0};
  faces.append(reinterpret_cast<const char*>(f), sizeof f);
  std::string mesh = chunk(0x4100, chunk(0x4110, verts) + chunk(0x4120, faces));
  std::string object = chunk(0x4000, std::string("tri", 4) + mesh);
  write_file(dir_ / "tri.3ds", chunk(0x4D4D, chunk(0x3D3D, object)));
  Scene s = parse_ok(one_object(R"({"type": "mesh", "file": "tri.3ds"})"));
  EXPECT_EQ(s.objects[0].mesh.triangle_count(), 1u);
  EXPECT_TRUE(has_position(s.objects[0].mesh, {0, 1, 0}));
}

// ---------------------------------------------------------------------------------------------
// The example scenes

TEST(ExampleScenes, AllLoadCleanly) {
  const fs::path folder = fs::path(RVR_SOURCE_DIR) / "scenes";
  int count = 0;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() != ".json") continue;
    ++count;
    Expected<Scene> s = rvr::load_scene_file(entry.path().string());
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_TRUE(s->warnings.empty()) << entry.path() << ": " << s->warnings[0];
    EXPECT_EQ(s->image.width, 640) << entry.path();
    EXPECT_EQ(s->image.height, 480) << entry.path();
    EXPECT_FALSE(s->lights.empty()) << entry.path();
    EXPECT_GE(s->objects.size(), 3u) << entry.path();
    bool has_mesh = false, has_plane = false;
    for (const rvr::Object& o : s->objects) {
      has_mesh |= o.type == rvr::ObjectType::Triangles && o.mesh.triangle_count() > 100;
      has_plane |= o.type == rvr::ObjectType::Plane;
    }
    EXPECT_TRUE(has_mesh) << entry.path();
    EXPECT_TRUE(has_plane) << entry.path();
  }
  EXPECT_GE(count, 3);
}

// image.exposure: read, range-checked, written back by the scene writer (rvr scenes --export)
// only when it is not 0, and overridden by SceneOverrides::exposure (--exposure).
TEST_F(SceneLoader, ExposureIsReadCheckedAndWrittenBack) {
  Expected<Scene> s = rvr::parse_scene(scene(R"("image": {"exposure": -1.5})"), "e.json", ".");
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->image.exposure, -1.5f);
  Expected<rvr::SceneDocument> doc = rvr::write_scene(*s, "e");
  ASSERT_TRUE(doc.ok());
  EXPECT_NE(doc->json.find("\"exposure\": -1.5"), std::string::npos) << doc->json;
  Expected<Scene> back = rvr::parse_scene(doc->json, "back.json", ".");
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->image.exposure, -1.5f);
  // The default, 0, is not written (documents written before the key stay as they were).
  Expected<Scene> plain = rvr::parse_scene(scene(R"("objects": [])"), "p.json", ".");
  EXPECT_EQ(plain->image.exposure, 0.0f);
  EXPECT_EQ(rvr::write_scene(*plain, "p")->json.find("exposure"), std::string::npos);
  Expected<Scene> bad = rvr::parse_scene(scene(R"("image": {"exposure": 64.5})"), "b.json", ".");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message,
            "b.json: image.exposure: must be between -64 and 64 stops, got 64.5");
  fs::path file = dir_ / "e.json";
  write_file(file, scene(R"("image": {"exposure": 3})"));
  rvr::SceneOverrides o;
  o.exposure = 1.0f;
  EXPECT_EQ(rvr::load_scene(file.string(), o)->image.exposure, 1.0f);
  o.exposure = -65.0f;
  EXPECT_FALSE(rvr::load_scene(file.string(), o).ok());
}

// A known diffuse square under a known light: diffuse 0.4, a point light of intensity 4 at
// distance 2 straight above the centre, no ambient, so the centre's colour is
// 0.4 x 4 / 2^2 = 0.4 at exposure 0 and exactly 2 x 0.4 = 0.8 (below clipping) at exposure 1,
// in every renderer of the table and through the prepared renderers alike; exactly a quarter
// of it at exposure -2.
TEST_F(SceneLoader, ExposureDoublesTheColourInEveryRenderer) {
  const std::string text = R"({"image": {"width": 33, "height": 33},
    "camera": {"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0]},
    "materials": {"paint": {"diffuse": [0.4, 0.4, 0.4]}},
    "lights": [{"type": "point", "position": [0, 0, 2], "intensity": [4, 4, 4]}],
    "objects": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "half_size": 1,
                 "material": "paint"}]})";
  Scene dark = rvr::parse_scene(text, "quad.json", ".").value();
  Scene bright = dark, dim = dark;
  bright.image.exposure = 1.0f;
  dim.image.exposure = -2.0f;  // 2^-2: a quarter
  const size_t centre = 16 * 33 + 16;
  for (const rvr::RendererChoice& choice : rvr::renderer_choices()) {
    SCOPED_TRACE(choice.name);
    rvr::RenderOptions options;
    options.mode = rvr::RenderMode::Local;
    auto prepared_dark = rvr::prepare_renderer(choice, dark, {}, options);
    auto prepared_bright = rvr::prepare_renderer(choice, bright, {}, options);
    ASSERT_TRUE(prepared_dark.ok() && prepared_bright.ok());
    auto renderer = choice.info->create({});
    ASSERT_TRUE(renderer.ok());
    for (int prepared = 0; prepared < 2; ++prepared) {
      Expected<rvr::RenderOutput> a =
          prepared ? prepared_dark.value()->render() : renderer.value()->render(dark, options);
      Expected<rvr::RenderOutput> b =
          prepared ? prepared_bright.value()->render() : renderer.value()->render(bright, options);
      ASSERT_TRUE(a.ok() && b.ok());
      glm::vec3 c0 = a->buffers.colour[centre], c1 = b->buffers.colour[centre];
      EXPECT_NEAR(c0.g, 0.4f, 1e-4f);
      EXPECT_EQ(c1, 2.0f * c0);  // a power of two: exact
      EXPECT_LT(c1.g, 1.0f);
      // Every pixel, background included, is the same transform of the one at exposure 0.
      for (size_t i = 0; i < a->buffers.colour.size(); ++i) {
        ASSERT_EQ(b->buffers.colour[i], 2.0f * a->buffers.colour[i]) << i;
      }
    }
    Expected<rvr::RenderOutput> d = renderer.value()->render(dim, options);
    ASSERT_TRUE(d.ok());
    Expected<rvr::RenderOutput> a = renderer.value()->render(dark, options);
    EXPECT_EQ(d->buffers.colour[centre], 0.25f * a->buffers.colour[centre]);
  }
}

}  // namespace
