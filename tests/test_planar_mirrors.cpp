// The z-buffers' planar mirrors and ior-1 layers (raster/src/planar_mirrors.h): a reflected view
// per mirror seen, clipped at the mirror, and a view without the layer per layer seen,
// composited by the shading equation, recursing to --max-depth. Held to the tracer's reflection
// and transmitted rays with primary visibility's tolerance.
#include <gtest/gtest.h>
#include <stdint.h>

#include <algorithm>
#include <cstddef>
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
#include "rvr/core/shapes/square.h"
#include "rvr/core/texture.h"
#include "rvr/scene_io/scene_loader.h"
#include "table_render.h"

namespace rvr {
namespace {

// Two mirrors turned towards each other (each sees the other, so reflections recurse), two balls
// and a floor. Every surface only glows (no lights, no ambient): a pixel's colour is its own
// emission, or (1 - m) of a mirror's plus m of what the mirror shows, so the colour names the
// chain of surfaces a pixel sees and both loop orders compute it with the same float operations.
// Balls as the z-buffers' tessellation in both (SphereMode::Mesh): the same triangles.
constexpr const char* kTwoMirrors = R"({
  "format": "rvr-scene/1",
  "image": { "width": 160, "height": 120, "background": [0.05, 0.05, 0.05] },
  "camera": { "eye": [0.3, 1.4, 5], "target": [0, 0.9, 0], "up": [0, 1, 0], "fov_y_deg": 50 },
  "ambient": [0, 0, 0],
  "materials": {
    "floor":   { "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.2, 0.25, 0.6] },
    "red":     { "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.9, 0.1, 0.1] },
    "green":   { "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.1, 0.8, 0.2] },
    "mirror":  { "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.3, 0.3, 0.1],
                 "mirror": 0.75 },
    "mirror2": { "diffuse": [0, 0, 0], "specular": [0, 0, 0], "emission": [0.1, 0.3, 0.3],
                 "mirror": 0.6 }
  },
  "objects": [
    { "name": "floor", "type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
      "half_size": 4, "material": "floor" },
    { "name": "left mirror", "type": "plane", "point": [-1.3, 1.2, -0.6],
      "normal": [0.8, 0, 0.6], "half_size": 1.1, "material": "mirror" },
    { "name": "right mirror", "type": "plane", "point": [1.5, 1.1, -0.4],
      "normal": [-0.8, 0, 0.6], "half_size": 1.0, "material": "mirror2" },
    { "name": "red ball", "type": "sphere", "center": [0.1, 0.5, 0.4], "radius": 0.5,
      "material": "red" },
    { "name": "green ball", "type": "sphere", "center": [-0.9, 0.4, 3.0], "radius": 0.35,
      "material": "green" }
  ]
})";
constexpr uint32_t kLeftMirror = 1, kRightMirror = 2;

// Primary visibility's tolerance (test_conformance): the two agree at every pixel but on edge
// ties, a float rounding on either side of an edge, at most 1 pixel in 1000. Agreeing pixels
// see the same surfaces and compute the same floats: 1e-6 is rounding, a wrong surface in the
// chain differs by at least 0.01 here.
constexpr double kMinAgreement = 0.999;
constexpr float kSameColour = 1e-6f;

Scene two_mirrors() {
  Expected<Scene> scene = load_scene_text(kTwoMirrors, "two_mirrors", ".");
  EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().message);
  return scene.ok() ? std::move(scene).value() : Scene{};
}

RenderOutput render(const std::string& renderer, const Scene& scene, int max_depth) {
  RenderOptions options;
  options.mode = RenderMode::Full;
  options.spheres = SphereMode::Mesh;
  options.max_depth = max_depth;
  return test::table_render(renderer, scene, options);
}

// The same mirrors with the balls lit by a point light above them: a Blinn-Phong highlight,
// which moves with the eye, and no diffuse term, so that where the balls shadow their own far
// sides (shadow maps and shadow rays cut the terminator differently) the light adds nothing.
Scene two_mirrors_lit() {
  Scene scene = two_mirrors();
  for (uint32_t ball : {3u, 4u}) {
    Material& m = scene.materials[scene.objects[ball].material];
    m.specular = glm::vec3(0.8f);
    m.shininess = 20.0f;
  }
  scene.ambient = glm::vec3(0.05f);
  Light light;
  light.type = LightType::Point;
  light.position = {0.2f, 4.0f, 2.0f};
  light.intensity = glm::vec3(12.0f);
  scene.lights.push_back(light);
  return scene;
}

// How many pixels' colours differ by more than `by`.
size_t pixels_differing(const FrameBuffers& a, const FrameBuffers& b, float by) {
  size_t n = 0;
  for (size_t i = 0; i < b.pixel_count(); ++i) n += test::colour_difference(a, b, i) > by;
  return n;
}

// The pixels of `a` whose colour is not the tracer's (`b`), and of those the ones away from
// every edge of the tracer's image (where no tie can explain them).
struct Disagreement {
  size_t differing = 0, away_from_edges = 0;
};
Disagreement disagreement(const FrameBuffers& a, const FrameBuffers& b) {
  Disagreement d;
  for (int y = 0; y < b.height; ++y)
    for (int x = 0; x < b.width; ++x) {
      const size_t i = size_t(y) * size_t(b.width) + size_t(x);
      if (test::colour_difference(a, b, i) <= kSameColour) continue;
      ++d.differing;
      if (!test::beside_an_edge(b, x, y, kSameColour)) ++d.away_from_edges;
    }
  return d;
}

// The z-buffer's frame `z` is the tracer's `t` but on edge ties: primary visibility's tolerance.
void expect_the_tracers_image(const FrameBuffers& z, const FrameBuffers& t,
                              const std::string& where) {
  const Disagreement d = disagreement(z, t);
  EXPECT_LE(double(d.differing), (1.0 - kMinAgreement) * double(t.pixel_count())) << where;
  EXPECT_EQ(d.away_from_edges, 0u) << where;
}

// The pixels of `fb` whose answer is not `on_them` where its own surface is one of the two
// mirrors, or not none elsewhere (every pixel when fb has no answers).
size_t wrong_answers(const FrameBuffers& fb, EffectAnswer on_them) {
  if (fb.answer.size() != fb.pixel_count()) return fb.pixel_count();
  size_t wrong = 0;
  for (size_t i = 0; i < fb.pixel_count(); ++i) {
    const bool mirror = fb.object_id[i] == kLeftMirror || fb.object_id[i] == kRightMirror;
    wrong += fb.answer[i] != uint8_t(mirror ? on_them : EffectAnswer::None);
  }
  return wrong;
}

class PlanarMirrors : public ::testing::TestWithParam<const char*> {};

// Every pixel, mirror pixels included, at every recursion limit: the z-buffer's colour is the
// tracer's but on edge ties of the image it shows (primary edges or reflected ones).
TEST_P(PlanarMirrors, AgreeWithTheTracersReflectionRaysAtEveryDepth) {
  const Scene scene = two_mirrors();
  for (int max_depth : {0, 1, 2, 5}) {
    // The longest chain of mirrors this geometry has: a ray reflected twice between the two
    // leaves them (a reflected view counts only where its own mirror is seen).
    constexpr int kLongestChain = 2;
    const RenderOutput z = render(GetParam(), scene, max_depth);
    const RenderOutput t = render("raytrace", scene, max_depth);
    const FrameBuffers &a = z.buffers, &b = t.buffers;
    ASSERT_EQ(a.pixel_count(), b.pixel_count());
    size_t mirror_pixels = 0;
    for (size_t i = 0; i < b.pixel_count(); ++i)
      mirror_pixels += b.object_id[i] == kLeftMirror || b.object_id[i] == kRightMirror;
    const std::string where = std::string(GetParam()) + " max_depth " + std::to_string(max_depth);
    // Something to agree on: both mirrors fill a fifth of the frame.
    EXPECT_GT(mirror_pixels, a.pixel_count() / 5) << where;
    expect_the_tracers_image(a, b, where);
    // The views drawn: none at depth 0, and the two mirrors see each other to the limit.
    EXPECT_EQ(z.stats.at("mirror.depth"), double(std::min(max_depth, kLongestChain))) << where;
    EXPECT_EQ(z.stats.at("mirror.views") > 0, max_depth > 0) << where;
    EXPECT_EQ(z.stats.at("mirror.pixels_at_limit") > 0, max_depth < kLongestChain) << where;
    // Every mirror pixel names the reflected view (the limit at depth 0), no other pixel any.
    EXPECT_EQ(
        wrong_answers(a, max_depth == 0 ? EffectAnswer::AtLimit : EffectAnswer::ReflectedView), 0u)
        << where;
  }
}

// Two mirrors face each other square on, the camera between them looking along the corridor:
// every level of reflection sees the other mirror again, so views recurse to the limit, and at
// every limit the image is still the tracer's but on edge ties.
TEST_P(PlanarMirrors, FacingMirrorsRecurseToTheLimit) {
  Scene scene = two_mirrors();
  scene.objects[kLeftMirror].plane = {{-1.5f, 1.2f, -1.0f}, {1.0f, 0.0f, 0.0f}, 3.0f};
  scene.objects[kRightMirror].plane = {{1.5f, 1.2f, -1.0f}, {-1.0f, 0.0f, 0.0f}, 3.0f};
  scene.camera.eye = {1.0f, 1.3f, 1.5f};
  scene.camera.target = {-1.5f, 1.0f, 0.3f};
  for (int max_depth : {3, 6}) {
    const RenderOutput z = render(GetParam(), scene, max_depth);
    const RenderOutput t = render("raytrace", scene, max_depth);
    const std::string where = std::string(GetParam()) + " max_depth " + std::to_string(max_depth);
    expect_the_tracers_image(z.buffers, t.buffers, where);
    EXPECT_EQ(z.stats.at("mirror.depth"), double(max_depth)) << where;
    EXPECT_GT(z.stats.at("mirror.pixels_at_limit"), 0.0) << where;
  }
}

// Without the reflected views (every mirror at the limit from the start) the mirrors lose what
// they show: the agreement above is the reflections', not the scene's.
TEST_P(PlanarMirrors, TheReflectionsAreWhatTheMirrorsShow) {
  const Scene scene = two_mirrors();
  const RenderOutput none = render(GetParam(), scene, 0);
  const RenderOutput t = render("raytrace", scene, 5);
  EXPECT_GT(pixels_differing(none.buffers, t.buffers, 0.01f), t.buffers.pixel_count() / 5);
}

// A reflected view shades towards the eye reflected in its mirrors (the direction the tracer's
// reflection ray arrives from): the balls' highlights, seen in the mirrors, sit where the
// tracer's do. Primary visibility's colour bound (test_conformance: 1e-3 per pixel, the same
// equation on float inputs) everywhere but on 1 pixel in 1000 (the edge ties).
TEST_P(PlanarMirrors, ReflectionsAreShadedFromTheReflectedEye) {
  const Scene scene = two_mirrors_lit();
  const RenderOutput z = render(GetParam(), scene, 5);
  const RenderOutput t = render("raytrace", scene, 5);
  EXPECT_LE(double(pixels_differing(z.buffers, t.buffers, 1e-3f)),
            (1.0 - kMinAgreement) * double(t.buffers.pixel_count()));
}

// The same scene with the left mirror a tinted pane of ior 1 (the tracer's transmitted ray goes
// straight on: the over operator) and the right one both a mirror and such a pane: every pixel,
// layers included, at every recursion limit, is the tracer's but on edge ties. A layer's view
// leaves the layer out, so what it shows is the first surface beyond it, as the ray meets it.
Scene two_layers() {
  Scene scene = two_mirrors();
  Material& left = scene.materials[scene.objects[kLeftMirror].material];
  left.mirror = 0.0f;
  left.transparency = 0.7f;
  left.ior = 1.0f;
  Material& right = scene.materials[scene.objects[kRightMirror].material];
  right.mirror = 0.4f;
  right.transparency = 0.35f;
  right.ior = 1.0f;
  return scene;
}

TEST_P(PlanarMirrors, TransparentLayersAreTheOverOperatorAtEveryDepth) {
  const Scene scene = two_layers();
  for (int max_depth : {0, 1, 2, 5}) {
    const RenderOutput z = render(GetParam(), scene, max_depth);
    const RenderOutput t = render("raytrace", scene, max_depth);
    const std::string where = std::string(GetParam()) + " max_depth " + std::to_string(max_depth);
    expect_the_tracers_image(z.buffers, t.buffers, where);
    // Each pane's own pixels name their answer: a layer's view (the right pane is also a
    // mirror: its transmitted share names it), at depth 0 the limit; nothing elsewhere.
    EXPECT_EQ(
        wrong_answers(z.buffers, max_depth == 0 ? EffectAnswer::AtLimit : EffectAnswer::LayerView),
        0u)
        << where;
    // A view behind each pane seen (and, through the right one's reflection, the left one's).
    EXPECT_EQ(z.stats.count("layer.views") > 0, max_depth > 0) << where;
    if (max_depth > 0) {
      EXPECT_GE(z.stats.at("layer.views"), 2.0) << where;
    }
  }
  // Without the views behind them the panes lose what they show.
  const RenderOutput none = render(GetParam(), scene, 0);
  const RenderOutput t = render("raytrace", scene, 5);
  size_t pane_pixels = 0;
  for (size_t i = 0; i < t.buffers.pixel_count(); ++i)
    pane_pixels += t.buffers.object_id[i] == kLeftMirror || t.buffers.object_id[i] == kRightMirror;
  EXPECT_GT(pixels_differing(none.buffers, t.buffers, 0.01f), pane_pixels / 2);
}

// A planar mirror whose transparency has another ior is not a layer: its transparency is left
// out, said by name, and its mirror still reflected.
TEST_P(PlanarMirrors, ARefractingPlanarMirrorIsNamedInAWarning) {
  Scene scene = two_mirrors();
  Material& left = scene.materials[scene.objects[kLeftMirror].material];
  left.transparency = 0.2f;
  left.ior = 1.5f;
  const RenderOutput out = render(GetParam(), scene, 5);
  bool named = false;
  for (const std::string& w : out.warnings)
    named |=
        w.find("transparency not rendered on 1 planar mirror (left mirror)") != std::string::npos;
  EXPECT_TRUE(named);
  EXPECT_EQ(out.stats.count("layer.views"), 0u);
  EXPECT_GT(out.stats.at("mirror.views"), 0.0);
}

// The mirrors' planes are found from their meshes; a curved mirror is said, by name, and drawn
// with its local share only.
TEST_P(PlanarMirrors, ACurvedMirrorIsNamedInAWarning) {
  Scene scene = make_builtin_scene("cornell").value();
  scene.image.width = 64;
  scene.image.height = 48;
  RenderOptions options;
  options.mode = RenderMode::Full;
  const RenderOutput out = test::table_render(GetParam(), scene, options);
  bool named = false;
  for (const std::string& w : out.warnings)
    named |=
        w.find("curved mirror") != std::string::npos && w.find("mirror ball") != std::string::npos;
  EXPECT_TRUE(named);
  EXPECT_EQ(out.stats.count("mirror.views"), 0u);
}

INSTANTIATE_TEST_SUITE_P(ZBuffers, PlanarMirrors, ::testing::Values("softraster", "raster"));

}  // namespace
}  // namespace rvr
