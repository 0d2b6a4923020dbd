// The z-buffers' cube environment maps (raster/src/environment_maps.h): a curved mirror and a
// transparent ball shown what a cube map drawn at their centre sees. The map's one known error
// is parallax (it sees from the centre, not from the surface point): against an environment far
// away compared with the object, that error vanishes and the map must give the tracer's colour
// wherever no edge of the reflected scene passes; near, the error must show.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "colour_edges.h"
#include "rvr/core/effect_answer.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/texture.h"
#include "rvr/scene_io/scene_loader.h"
#include "table_render.h"

namespace rvr {
namespace {

// An object at the origin (a ball of radius 1, or a sheet: `shape`) inside a box whose six walls
// only glow, each its own colour, up to `distance` from the centre. No lights and no ambient: a
// wall's colour is its emission, the object's (1 - mirror - transparency) · its emission plus what
// its rays meet. The ball as the z-buffers' tessellation in both renderers (SphereMode::Mesh): the
// same triangles and normals. The camera sees as far as any wall.
constexpr const char* kBallShape = R"("type": "sphere", "center": [0, 0, 0], "radius": 1)";
constexpr const char* kSheetShape =
    R"("type": "plane", "point": [0, 0, 0], "normal": [0.3, 0.2, 1], "half_size": 1)";

std::string box_scene(double distance, const char* shape, const std::string& material) {
  // Each wall at its own distance, so that the box is not centred on the object and every face
  // of its map sees several walls; each a square large enough to close the box.
  const auto wall = [&](const char* name, int axis, double share) {
    double point[3] = {0, 0, 0}, normal[3] = {0, 0, 0};
    point[axis] = share * distance;
    normal[axis] = share > 0 ? -1 : 1;
    return fmt::format(
        R"({{ "name": "{}", "type": "plane", "point": [{}, {}, {}], "normal": [{}, {}, {}],
      "half_size": {}, "material": "{}" }})",
        name, point[0], point[1], point[2], normal[0], normal[1], normal[2], 2.0 * distance, name);
  };
  return fmt::format(R"({{
  "format": "rvr-scene/1",
  "image": {{ "width": 160, "height": 120, "background": [0, 0, 0] }},
  "camera": {{ "eye": [0.6, 0.9, 2.8], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 45,
              "far": 100000 }},
  "ambient": [0, 0, 0],
  "materials": {{
    "px": {{ "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.9, 0.1, 0.1] }},
    "nx": {{ "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.1, 0.8, 0.2] }},
    "py": {{ "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.2, 0.3, 0.9] }},
    "ny": {{ "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.8, 0.8, 0.1] }},
    "pz": {{ "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.7, 0.2, 0.8] }},
    "nz": {{ "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.1, 0.7, 0.7] }},
    "ball": {}
  }},
  "objects": [
    {{ "name": "ball", {}, "material": "ball" }},
    {}, {}, {}, {}, {}, {}
  ]
}})",
                     material, shape, wall("px", 0, 1.0), wall("nx", 0, -0.6), wall("py", 1, 0.8),
                     wall("ny", 1, -0.5), wall("pz", 2, 0.9), wall("nz", 2, -0.7));
}

constexpr const char* kMirrorBall =
    R"({ "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.2, 0.2, 0.2], "mirror": 0.8 })";
// Glass. As a sheet it has one interface, so the tracer's transmitted ray goes on as Snell's law
// bent it at the first, as the map's lookup does; a ball bends it again where it leaves, which
// the map's lookup follows in closed form. Only emission: the back's local colour is the front's.
constexpr const char* kGlass =
    R"({ "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.2, 0.2, 0.2],
         "transparency": 0.7, "ior": 1.5 })";
constexpr uint32_t kBall = 0;

Scene load(const std::string& text) {
  Expected<Scene> scene = load_scene_text(text, "box", ".");
  EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().message);
  return scene.ok() ? std::move(scene).value() : Scene{};
}

// Maps of 1024 texels a side: a texel spans 2/1024 rad at a face's centre, less than half a
// pixel's step in transmitted direction through the sheet (45° over 120 rows, bent by 1/1.5),
// so the bilinear lookup blends two walls only within a pixel of their edge.
constexpr int kMapSize = 1024;

RenderOutput render(const std::string& renderer, const Scene& scene, int max_depth = 5) {
  RenderOptions options;
  options.mode = RenderMode::Full;
  options.spheres = SphereMode::Mesh;
  options.max_depth = max_depth;
  options.cube_map_size = kMapSize;
  return test::table_render(renderer, scene, options);
}

// A colour the two compute from the same wall: float rounding of the bilinear weights and of
// the shading sum. The walls' colours differ by 0.1 or more in some channel.
constexpr float kSameColour = 1e-4f;

// The ball's pixels in both frames, and of those the ones away from every edge of the tracer's
// image (no neighbour of another colour: there a pixel's one ray and the map's bilinear texels
// may fall on either side) whose colour is not the tracer's.
struct BallAgreement {
  size_t ball = 0, away_from_edges = 0, differing = 0;
};
BallAgreement ball_agreement(const FrameBuffers& z, const FrameBuffers& t) {
  BallAgreement a;
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      const size_t i = size_t(y) * size_t(t.width) + size_t(x);
      if (t.object_id[i] != kBall || z.object_id[i] != kBall ||
          test::beside_an_edge(t, x, y, kSameColour))
        continue;
      ++a.away_from_edges;
      a.differing += test::colour_difference(z, t, i) > kSameColour;
    }
  for (size_t i = 0; i < t.pixel_count(); ++i) a.ball += t.object_id[i] == kBall;
  return a;
}

class EnvironmentMaps : public ::testing::TestWithParam<const char*> {};

// Walls 5000 to 10^4 radii away: the parallax of a map seen from the centre instead of the surface
// point is at most 2·10^-4 rad, a tenth of a texel and far less than a pixel's step in reflected or
// transmitted direction. So every pixel of the mirror ball, the glass sheet and the glass ball
// away from an edge shows the tracer's wall.
TEST_P(EnvironmentMaps, FarEnvironmentGivesTheTracersColour) {
  for (const auto& [shape, material] :
       {std::pair{kBallShape, kMirrorBall}, {kSheetShape, kGlass}, {kBallShape, kGlass}}) {
    const Scene scene = load(box_scene(1e4, shape, material));
    const std::string ball = material;
    const RenderOutput z = render(GetParam(), scene);
    const RenderOutput t = render("raytrace", scene);
    ASSERT_EQ(z.buffers.pixel_count(), t.buffers.pixel_count());
    const BallAgreement a = ball_agreement(z.buffers, t.buffers);
    const std::string where = std::string(GetParam()) + " " + ball;
    // Something to agree on: the ball fills a good part of the frame, most of it away from edges.
    EXPECT_GT(a.ball, t.buffers.pixel_count() / 8) << where;
    EXPECT_GT(a.away_from_edges, a.ball / 2) << where;
    EXPECT_EQ(a.differing, 0u) << where;
    EXPECT_EQ(z.stats.at("cube_map.faces"), 6.0) << where;
  }
}

// Walls 1.75 to 3.5 radii away: the map sees them from the centre, the tracer from the surface, and
// the reflected walls' edges move by up to about 1/1.75 rad, many pixels: more than 1 in 100 ball
// pixels away from any edge of the tracer's image show another wall. The test sees the technique's
// known error.
TEST_P(EnvironmentMaps, NearEnvironmentShowsTheParallaxError) {
  const Scene scene = load(box_scene(3.5, kBallShape, kMirrorBall));
  const BallAgreement a =
      ball_agreement(render(GetParam(), scene).buffers, render("raytrace", scene).buffers);
  EXPECT_GT(a.differing, a.away_from_edges / 100) << GetParam();
}

// At the recursion limit the mirrored and transmitted shares are dropped, as the tracer drops
// them, and no map is drawn.
TEST_P(EnvironmentMaps, RecursionLimitDropsTheShares) {
  for (const auto& [shape, material] :
       {std::pair{kBallShape, kMirrorBall}, {kSheetShape, kGlass}}) {
    const Scene scene = load(box_scene(1e4, shape, material));
    const std::string ball = material;
    const RenderOutput z = render(GetParam(), scene, 0);
    const RenderOutput t = render("raytrace", scene, 0);
    const BallAgreement a = ball_agreement(z.buffers, t.buffers);
    EXPECT_GT(a.away_from_edges, a.ball / 2) << GetParam() << " " << ball;
    EXPECT_EQ(a.differing, 0u) << GetParam() << " " << ball;
    EXPECT_EQ(z.stats.at("cube_map.faces"), 0.0) << GetParam() << " " << ball;
  }
}

// The answer AOV (rvr/core/effect_answer.h) names the technique at every pixel whose own
// surface is the object, and nothing elsewhere: a mirror ball's map, a sheet's first interface
// only, a glass ball's two interfaces, the recursion limit, no map at size 0.
TEST_P(EnvironmentMaps, EachPixelOfTheObjectNamesItsAnswer) {
  struct Case {
    const char* shape;
    const char* material;
    int max_depth, map_size;
    EffectAnswer answer;
  };
  for (const Case& c : {Case{kBallShape, kMirrorBall, 5, 64, EffectAnswer::CubeMapReflection},
                        Case{kSheetShape, kGlass, 5, 64, EffectAnswer::FirstInterfaceOnly},
                        Case{kBallShape, kGlass, 5, 64, EffectAnswer::CubeMapRefraction},
                        Case{kBallShape, kMirrorBall, 0, 64, EffectAnswer::AtLimit},
                        Case{kBallShape, kGlass, 5, 0, EffectAnswer::LeftOut}}) {
    const Scene scene = load(box_scene(1e4, c.shape, c.material));
    RenderOptions options;
    options.mode = RenderMode::Full;
    options.max_depth = c.max_depth;
    options.cube_map_size = c.map_size;
    const FrameBuffers fb = test::table_render(GetParam(), scene, options).buffers;
    const std::string where = std::string(GetParam()) + " " + effect_answer_name(c.answer);
    ASSERT_EQ(fb.answer.size(), fb.pixel_count()) << where;
    size_t object = 0, wrong = 0;
    for (size_t i = 0; i < fb.pixel_count(); ++i) {
      const bool own = fb.object_id[i] == kBall;
      object += own;
      wrong += fb.answer[i] != uint8_t(own ? c.answer : EffectAnswer::None);
    }
    EXPECT_GT(object, fb.pixel_count() / 8) << where;
    EXPECT_EQ(wrong, 0u) << where;
  }
}

// Screen-space reflections: the mirror ball's pixel at the image centre faces the camera, so
// its reflected ray comes straight back past the eye and leaves the view (off screen); every
// ball pixel carries its march's outcome, as many of each as the ssr stats count.
TEST_P(EnvironmentMaps, ScreenSpaceReflectionsNameEachMarchsOutcome) {
  const Scene scene = load(box_scene(3.5, kBallShape, kMirrorBall));
  RenderOptions options;
  options.mode = RenderMode::Full;
  options.zbuffer_reflection = ZBufferReflection::Ssr;
  const RenderOutput out = test::table_render(GetParam(), scene, options);
  const FrameBuffers& fb = out.buffers;
  ASSERT_EQ(fb.answer.size(), fb.pixel_count());
  EXPECT_EQ(fb.answer[fb.index(fb.width / 2, fb.height / 2)], uint8_t(EffectAnswer::SsrOffScreen))
      << GetParam();
  std::map<std::string, double> counted;
  for (size_t i = 0; i < fb.pixel_count(); ++i)
    if (fb.answer[i] != uint8_t(EffectAnswer::None))
      counted[effect_answer_name(EffectAnswer(fb.answer[i]))] += 1.0;
  EXPECT_EQ(counted["ssr_hit"], out.stats.at("ssr.hits")) << GetParam();
  EXPECT_EQ(counted["ssr_background"], out.stats.at("ssr.background")) << GetParam();
  EXPECT_EQ(counted["ssr_off_screen"], out.stats.at("ssr.off_screen")) << GetParam();
  EXPECT_EQ(counted["ssr_hidden"], out.stats.at("ssr.hidden")) << GetParam();
  EXPECT_GT(counted["ssr_hit"], 0.0) << GetParam();
}

// --cube-map-size 0: no map, the ball's local colour at full weight, said in a warning.
TEST_P(EnvironmentMaps, SizeZeroLeavesTheLocalColourAndSaysSo) {
  const Scene scene = load(box_scene(1e4, kBallShape, kMirrorBall));
  RenderOptions options;
  options.mode = RenderMode::Full;
  options.cube_map_size = 0;
  const RenderOutput z = test::table_render(GetParam(), scene, options);
  const FrameBuffers& fb = z.buffers;
  size_t ball = 0;
  for (size_t i = 0; i < fb.pixel_count(); ++i)
    if (fb.object_id[i] == kBall) {
      ++ball;
      ASSERT_NEAR(fb.colour[i].x, 0.2f, 1e-6f) << GetParam();
    }
  EXPECT_GT(ball, 0u);
  ASSERT_EQ(z.warnings.size(), 1u) << GetParam();
  EXPECT_NE(z.warnings[0].find("reflection on 1 curved mirror (ball) not rendered"),
            std::string::npos)
      << z.warnings[0];
}

INSTANTIATE_TEST_SUITE_P(ZBuffers, EnvironmentMaps, ::testing::Values("softraster", "raster"));

}  // namespace
}  // namespace rvr
