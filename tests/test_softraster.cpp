// SoftRasterizer: the top-left fill rule, near-plane clipping, orientation, determinism across
// thread counts, agreement with the GL rasterizer and the ray tracer, and the cost AOV.
#include <gtest/gtest.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raster/soft_rasterizer.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"
#include "same_bytes.h"
#include "scene_builders.h"
#include "visibility_frame.h"

namespace rvr {
namespace {

RenderOutput render_soft(const Scene& scene, RenderMode mode = RenderMode::Local, int threads = 0,
                         bool hiz = true) {
  SoftRasterizer r;
  RenderOptions options;
  options.mode = mode;
  options.threads = threads;
  options.hiz = hiz;
  options.spheres = SphereMode::Mesh;
  Expected<RenderOutput> out = r.render(scene, options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return std::move(out).value();
}

void add_triangle(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material) {
  Object o;
  o.type = ObjectType::Triangles;
  o.material = material;
  o.mesh.positions = {a, b, c};
  o.mesh.triangles = {{0, 1, 2}};
  s.objects.push_back(o);
}

// A square split along its diagonal into two triangles of opposite winding. Its corners and
// the diagonal fall exactly on pixel centres (x.5, y.5), the ties the fill rule must break:
// each pixel of the square is drawn exactly once, the left and top edges are in, the right
// and bottom edges out.
TEST(SoftRasterizer, TopLeftRuleCoversSharedEdgesExactlyOnce) {
  Scene s = test::empty_scene(64, 64, {0, 0, 0}, {0, 0, -1}, 90.0f);
  uint32_t m = test::emissive(s, {1, 1, 1});
  // At z = -1 with a 90 degree field of view, screen x = 32 + 32 * world x (y flipped).
  const float lo = -15.5f / 32.0f, hi = 16.5f / 32.0f;
  const glm::vec3 tl(lo, -lo, -1), tr(hi, -lo, -1), br(hi, -hi, -1), bl(lo, -hi, -1);
  Object o;
  o.type = ObjectType::Triangles;
  o.material = m;
  o.mesh.positions = {tl, tr, br, bl};
  o.mesh.triangles = {{0, 1, 2}, {0, 3, 2}};  // counter-clockwise and clockwise
  s.objects.push_back(o);

  RenderOutput out = render_soft(s);
  const FrameBuffers& fb = out.buffers;
  size_t covered = 0, diagonal_first = 0, diagonal_second = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      size_t i = fb.index(x, y);
      bool inside = x >= 16 && x < 48 && y >= 16 && y < 48;
      EXPECT_EQ(fb.cost[i], inside ? 1.0f : 0.0f) << "pixel " << x << "," << y;
      covered += fb.object_id[i] != kNoId;
      if (x == y && inside) (fb.primitive_id[i] == 0 ? diagonal_first : diagonal_second)++;
    }
  }
  EXPECT_EQ(covered, 32u * 32u);
  EXPECT_EQ(diagonal_first + diagonal_second, 32u);
  EXPECT_DOUBLE_EQ(out.stats.at("overdraw"), 1.0);
}

TEST(SoftRasterizer, RowZeroIsTheTop) {
  Scene s = test::empty_scene(32, 32, {0, 0, 3}, {0, 0, 0}, 60.0f);
  uint32_t m = test::emissive(s, {1, 0, 0});
  add_triangle(s, {-1, 0.2f, 0}, {1, 0.2f, 0}, {0, 1, 0}, m);  // above the centre
  const FrameBuffers& fb = render_soft(s).buffers;
  size_t top = 0, bottom = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) (y < 16 ? top : bottom) += fb.object_id[fb.index(x, y)] != kNoId;
  EXPECT_GT(top, 20u);
  EXPECT_EQ(bottom, 0u);
}

// Triangles crossing the near plane, one with corners behind the eye: clipped in clip space,
// so nothing wraps around, depth never goes below near, and what is seen matches the tracer
// (whose rays also start at near).
TEST(SoftRasterizer, NearPlaneClippingHasNoArtefacts) {
  Scene s = test::empty_scene(96, 64, {0, 0, 0}, {0, 0, -1}, 60.0f);
  s.camera.near = 0.5f;
  uint32_t floor = test::add_material(s, {0.7f, 0.6f, 0.5f});
  uint32_t wall = test::add_material(s, {0.2f, 0.5f, 0.8f});
  s.lights.push_back({LightType::Point, {0, 2, 0}, {}, {}, {}, {5, 5, 5}, 4});
  add_triangle(s, {-3, -0.5f, 2}, {3, -0.5f, 2}, {0, -0.5f, -8}, floor);        // behind the eye
  add_triangle(s, {-1.5f, -1, -0.2f}, {1.5f, -1, -0.2f}, {0, 1.5f, -3}, wall);  // through near

  RenderOutput soft = render_soft(s);
  EXPECT_GT(soft.stats.at("triangles.clipped"), 0.0);
  const FrameBuffers& fb = soft.buffers;
  size_t covered = 0;
  for (size_t i = 0; i < fb.pixel_count(); ++i) {
    ASSERT_TRUE(std::isfinite(fb.colour[i].x + fb.colour[i].y + fb.colour[i].z)) << i;
    if (fb.object_id[i] == kNoId) continue;
    ++covered;
    EXPECT_GE(fb.depth[i], s.camera.near) << i;
    EXPECT_LE(fb.cost[i], 2.0f) << i;
  }
  EXPECT_GT(covered, fb.pixel_count() / 4);

  auto tracer = make_renderer("raytrace");
  ASSERT_TRUE(tracer.ok());
  RenderOptions options;
  Expected<RenderOutput> traced = tracer.value()->render(s, options);
  ASSERT_TRUE(traced.ok());
  ComparisonMetrics m = compare_buffers(fb, traced->buffers);
  EXPECT_GE(m.visibility.id_agreement, 0.99);
  EXPECT_EQ(m.visibility.classes.not_edge(), 0u);
  EXPECT_LE(m.depth.max_rel_error, 1e-3);
}

// Tiles may run on any thread in any order; each tile keeps submission order, so the bytes
// are the same.
TEST(SoftRasterizer, SameBytesWithOneAndTwoThreads) {
  Expected<Scene> scene = make_builtin_scene("soup:20000");
  ASSERT_TRUE(scene.ok());
  RenderOutput a = render_soft(*scene, RenderMode::Local, 1);
  RenderOutput b = render_soft(*scene, RenderMode::Local, 2);
  const FrameBuffers &fa = a.buffers, &fb = b.buffers;
  auto same = [](const auto& x, const auto& y) { return rvr::test::same_bytes(x, y); };
  EXPECT_TRUE(same(fa.colour, fb.colour));
  EXPECT_TRUE(same(fa.depth, fb.depth));
  EXPECT_TRUE(same(fa.object_id, fb.object_id));
  EXPECT_TRUE(same(fa.primitive_id, fb.primitive_id));
  EXPECT_TRUE(same(fa.normal, fb.normal));
  EXPECT_TRUE(same(fa.cost, fb.cost));
  EXPECT_EQ(a.stats.at("fragments.generated"), b.stats.at("fragments.generated"));
}

TEST(SoftRasterizer, AgreesWithTheGlRasterizerOnIds) {
  Expected<Scene> scene = make_builtin_scene("tessphere:20000");
  ASSERT_TRUE(scene.ok());
  RenderOutput soft = render_soft(*scene);
  GlRasterizer gl;
  Expected<RenderOutput> hard = gl.render(*scene, RenderOptions{});
  ASSERT_TRUE(hard.ok()) << hard.error().message;
  ComparisonMetrics m = compare_buffers(soft.buffers, hard->buffers);
  EXPECT_GE(m.visibility.id_agreement, 0.999) << m.visibility.mismatched_pixels;
  EXPECT_EQ(m.visibility.classes.not_edge(), 0u);
}

// Cost is every fragment generated, hidden or not: the depth complexity. Each quad rendered
// alone gives its coverage; their sum is the expected cost everywhere, and 8 where the
// rearmost (smallest on screen) quad is seen.
TEST(SoftRasterizer, CostIsDepthComplexity) {
  Expected<Scene> scene = make_builtin_scene("occluders:8");
  ASSERT_TRUE(scene.ok());
  RenderOutput all = render_soft(*scene, RenderMode::Visibility, 0, /*hiz=*/false);
  std::vector<float> complexity(all.buffers.pixel_count(), 0.0f);
  std::vector<bool> rear;
  for (size_t k = 0; k < scene->objects.size(); ++k) {
    Scene one = *scene;
    one.objects = {scene->objects[k]};
    const FrameBuffers& fb = render_soft(one, RenderMode::Visibility, 0, false).buffers;
    for (size_t i = 0; i < fb.pixel_count(); ++i) complexity[i] += fb.object_id[i] != kNoId;
    if (k + 1 == scene->objects.size())
      for (uint32_t id : fb.object_id) rear.push_back(id != kNoId);
  }
  size_t full_depth = 0;
  for (size_t i = 0; i < complexity.size(); ++i) {
    ASSERT_EQ(all.buffers.cost[i], complexity[i]) << "pixel " << i;
    if (rear[i]) {
      EXPECT_EQ(all.buffers.cost[i], 8.0f);
      ++full_depth;
    }
  }
  EXPECT_GT(full_depth, complexity.size() / 10);
  EXPECT_GT(all.stats.at("overdraw"), 1.0);
}

// Hierarchical z only skips work that the depth test would throw away: everything seen is the
// same bytes with it on or off. Drawn front to back, the occluders behind the first quad are
// rejected block by block; drawn back to front, every quad is nearer than what is there, and
// nothing is rejected. The cost AOV adds each rejection as 1/64 to the pixels of its block, so
// over the frame it sums to fragments + blocks rejected.
TEST(SoftRasterizer, HierarchicalZChangesNothingSeen) {
  auto same = [](const auto& x, const auto& y) { return rvr::test::same_bytes(x, y); };
  for (const char* name : {"occluders:16", "occluders_back:16", "tessphere:20000", "soup:2000",
                           "cornell", "spheres"}) {
    Expected<Scene> scene = make_builtin_scene(name);
    ASSERT_TRUE(scene.ok());
    RenderOutput on = render_soft(*scene, RenderMode::Local, 0, true);
    RenderOutput off = render_soft(*scene, RenderMode::Local, 0, false);
    EXPECT_TRUE(same(on.buffers.colour, off.buffers.colour)) << name;
    EXPECT_TRUE(same(on.buffers.depth, off.buffers.depth)) << name;
    EXPECT_TRUE(same(on.buffers.object_id, off.buffers.object_id)) << name;
    EXPECT_TRUE(same(on.buffers.primitive_id, off.buffers.primitive_id)) << name;
    EXPECT_TRUE(same(on.buffers.normal, off.buffers.normal)) << name;
    EXPECT_EQ(off.stats.at("hiz.blocks_rejected"), 0.0);
    EXPECT_LE(on.stats.at("fragments.generated"), off.stats.at("fragments.generated")) << name;
    double cost_sum = 0;
    for (float c : on.buffers.cost) cost_sum += c;
    ASSERT_EQ(on.buffers.width % 8, 0);
    ASSERT_EQ(on.buffers.height % 8, 0);
    EXPECT_DOUBLE_EQ(cost_sum,
                     on.stats.at("fragments.generated") + on.stats.at("hiz.blocks_rejected"))
        << name;
    const std::string n = name;
    if (n == "occluders:16") {
      EXPECT_GT(on.stats.at("hiz.blocks_rejected"), 1000.0);
      // 15 of the 16 quads lie behind the first wherever it covers them.
      EXPECT_LT(on.stats.at("fragments.generated"), 0.5 * off.stats.at("fragments.generated"));
    }
    if (n == "occluders_back:16") {
      EXPECT_EQ(on.stats.at("hiz.blocks_rejected"), 0.0);
    }
    if (n == "tessphere:20000") {  // its far half lies behind the near half drawn before it
      EXPECT_GT(on.stats.at("hiz.triangles_rejected"), 0.0);
    }
  }
}

// A triangle whose box spans two blocks is tested against each block's farthest depth: the
// block hidden behind a nearer occluder is rejected (counted once per triangle, 1/64 of a cost
// unit on each of its pixels) and its pixels get no fragment, while the other block's pixels
// are drawn. A rectangle 6x4 pixels wide (two triangles, each a box narrower than a block) lies
// across block columns 0 and 1 behind a quad covering column 0 (pixels x < 8) entirely.
TEST(SoftRasterizer, HierarchicalZRejectsTheHiddenBlockOfASmallTriangle) {
  Scene s = test::empty_scene(64, 64, {0, 0, 0}, {0, 0, -1}, 90.0f);
  uint32_t m = test::emissive(s, {1, 1, 1});
  // 90 degree field of view, 64 pixels: at depth d, screen (x, y) = (32 + 32 wx / d,
  // 32 - 32 wy / d). Corners on pixel boundaries, so no centre lies on an edge (the
  // rectangle's diagonal, 6y - 4x = 75 at centres, has no integer solution).
  auto at = [](float sx, float sy, float d) {
    return glm::vec3((sx - 32.0f) * d / 32.0f, (32.0f - sy) * d / 32.0f, -d);
  };
  auto add_rectangle = [&](float x0, float y0, float x1, float y1, float d) {
    Object o;
    o.type = ObjectType::Triangles;
    o.material = m;
    o.mesh.positions = {at(x0, y0, d), at(x1, y0, d), at(x1, y1, d), at(x0, y1, d)};
    o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
    s.objects.push_back(o);
  };
  add_rectangle(0, 0, 8, 64, 1.0f);    // the occluder, drawn first: block column 0
  add_rectangle(5, 16, 11, 20, 2.0f);  // behind it in column 0, alone in column 1
  for (bool hiz : {true, false}) {
    const FrameBuffers& fb = render_soft(s, RenderMode::Visibility, 0, hiz).buffers;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        const bool occluder = x < 8, behind = x >= 5 && x < 11 && y >= 16 && y < 20;
        float expected = float(occluder) + float(behind);
        // Both triangles of the rectangle reject block (0, 2): rows 16-23 of column 0.
        if (hiz && x < 8 && y >= 16 && y < 24) expected = 1.0f + 2.0f / 64.0f;
        if (hiz && x < 8 && behind) expected = 1.0f + 2.0f / 64.0f;
        EXPECT_EQ(fb.cost[fb.index(x, y)], expected) << x << "," << y << (hiz ? "" : " no hi-z");
        EXPECT_EQ(fb.object_id[fb.index(x, y)], occluder ? 0u
                                                : behind ? 1u
                                                         : kNoId)
            << x << "," << y;
      }
  }
}

// Triangles stream through in chunks of 262,144: a scene of several chunks gives the same bytes
// on one thread as on two, with and without hi-z, and the rasterizer's memory (the frame's
// z-buffer state plus one chunk) does not grow with the number of triangles.
TEST(SoftRasterizer, ManyChunksSameBytesBoundedMemory) {
  double memory[2] = {0, 0};
  int k = 0;
  for (const char* name : {"soup:600000", "soup:2400000"}) {
    Expected<Scene> scene = make_builtin_scene(name);
    ASSERT_TRUE(scene.ok());
    for (bool hiz : {true, false}) {
      RenderOutput a = render_soft(*scene, RenderMode::Local, 1, hiz);
      RenderOutput b = render_soft(*scene, RenderMode::Local, 2, hiz);
      EXPECT_EQ(a.buffers.colour, b.buffers.colour) << name;
      EXPECT_EQ(a.buffers.object_id, b.buffers.object_id) << name;
      EXPECT_EQ(a.buffers.cost, b.buffers.cost) << name;
      memory[k] = std::max(memory[k], a.stats.at("memory.raster_bytes"));
    }
    ++k;
  }
  // Four times the triangles, the same memory (to within the growth of one chunk's bins).
  EXPECT_LT(memory[1], 1.05 * memory[0]) << memory[0] << " then " << memory[1];
}

// One SoftRasterizer keeps its z-buffer state between renders and clears it: what it draws
// does not depend on what it drew before (another scene, another size, hi-z on or off, many
// triangles where the next has few).
TEST(SoftRasterizer, ReusedRendererDrawsWhatAFreshOneDraws) {
  auto same = [](const RenderOutput& a, const RenderOutput& b) {
    auto eq = [](const auto& x, const auto& y) { return rvr::test::same_bytes(x, y); };
    return eq(a.buffers.colour, b.buffers.colour) && eq(a.buffers.depth, b.buffers.depth) &&
           eq(a.buffers.object_id, b.buffers.object_id) &&
           eq(a.buffers.primitive_id, b.buffers.primitive_id) &&
           eq(a.buffers.normal, b.buffers.normal) && eq(a.buffers.cost, b.buffers.cost);
  };
  struct Case {
    const char* scene;
    bool hiz;
    int width;
    bool no_objects = false;  // every tile left empty: cleared without a triangle in it
  };
  const Case cases[] = {
      {"soup:20000", true, 160}, {"spheres", true, 160},       {"occluders:8", true, 160},
      {"spheres", false, 160},   {"tessphere:5000", true, 96}, {"soup:20000", true, 160},
      {"cornell", true, 160},    {"spheres", true, 160, true}, {"soup:20000", false, 160}};
  SoftRasterizer reused;
  for (const Case& c : cases) {
    Expected<Scene> scene = make_builtin_scene(c.scene);
    ASSERT_TRUE(scene.ok());
    scene->image.width = c.width;
    scene->image.height = c.width * 3 / 4;
    if (c.no_objects) scene->objects.clear();
    RenderOptions options;
    options.mode = RenderMode::Local;
    options.hiz = c.hiz;
    Expected<RenderOutput> again = reused.render(*scene, options);
    SoftRasterizer fresh_renderer;
    Expected<RenderOutput> fresh = fresh_renderer.render(*scene, options);
    ASSERT_TRUE(again.ok() && fresh.ok());
    EXPECT_TRUE(same(*again, *fresh)) << c.scene << (c.hiz ? "" : " no hi-z") << " " << c.width;
    EXPECT_EQ(again->stats.at("fragments.generated"), fresh->stats.at("fragments.generated"));
  }
}

// Visibility mode writes what visibility is and nothing more: depth, ids and cost as local mode
// writes them (visibility_frame.h), colour the background, normal 0, no shading time; without
// the cost AOV the cost is 0. Odd sizes: rows end inside a SIMD group and an 8x8 block.
TEST(SoftRasterizer, VisibilityModeWritesIdsDepthAndCostOnly) {
  for (const char* name : {"cornell", "spheres", "tessphere:1000"}) {
    Expected<Scene> loaded = make_builtin_scene(name);
    ASSERT_TRUE(loaded.ok()) << name;
    Scene scene = *loaded;
    scene.image.width = 203;
    scene.image.height = 151;
    for (bool hiz : {true, false}) {
      const std::string label = std::string(name) + (hiz ? "" : " no hi-z");
      SoftRasterizer r;  // one renderer, reused across modes, as the hybrid does
      RenderOptions options;
      options.hiz = hiz;
      options.mode = RenderMode::Local;
      RenderOutput local = r.render(scene, options).value();
      options.mode = RenderMode::Visibility;
      RenderOutput visibility = r.render(scene, options).value();
      options.cost_aov = false;
      RenderOutput no_cost = r.render(scene, options).value();
      test::expect_visibility_frame(scene, local.buffers, visibility.buffers, no_cost.buffers,
                                    label);
      EXPECT_EQ(visibility.stats.count("time.shade"), 0u) << label;
      EXPECT_EQ(visibility.stats.count("time.readback"), 1u) << label;
      EXPECT_EQ(local.stats.count("time.readback"), 0u) << label;
      for (const RenderOutput* out : {&local, &visibility})
        EXPECT_GE(out->stats.at("time.visibility"), out->stats.at("time.raster")) << label;
      EXPECT_EQ(visibility.stats.at("fragments.generated"), local.stats.at("fragments.generated"))
          << label;
      EXPECT_EQ(no_cost.stats.at("fragments.generated"), local.stats.at("fragments.generated"))
          << label;
      // The target keeps what the pass reads: no barycentrics (3 floats a pixel) without
      // shading, no fragment counts (a uint32_t a pixel) without the cost AOV.
      const double pixels = double(scene.image.width) * double(scene.image.height);
      EXPECT_EQ(local.stats.at("memory.raster_bytes") - visibility.stats.at("memory.raster_bytes"),
                12.0 * pixels)
          << label;
      EXPECT_EQ(
          visibility.stats.at("memory.raster_bytes") - no_cost.stats.at("memory.raster_bytes"),
          4.0 * pixels)
          << label;
    }
  }
}

// Without the cost AOV, local and full mode change only the cost, to 0.
TEST(SoftRasterizer, NoCostAovLeavesEveryOtherBufferAsItWas) {
  Expected<Scene> scene = make_builtin_scene("cornell");
  ASSERT_TRUE(scene.ok());
  for (RenderMode mode : {RenderMode::Local, RenderMode::Full}) {
    SoftRasterizer r;
    RenderOptions options;
    options.mode = mode;
    const FrameBuffers with = r.render(*scene, options).value().buffers;
    options.cost_aov = false;
    const FrameBuffers without = r.render(*scene, options).value().buffers;
    test::expect_only_the_cost_left_out(with, without, to_string(mode));
  }
}

// builtin:csg in full mode: every CSG object drawn, two depth passes per leaf, with no
// warning; the shadow maps drawn too.
TEST(SoftRasterizer, DrawsCsgObjectsLeafByLeafWithoutWarnings) {
  Expected<Scene> scene = make_builtin_scene("csg");
  ASSERT_TRUE(scene.ok());
  scene->image.width = 96;
  scene->image.height = 72;
  size_t objects = 0, leaves = 0;
  std::function<void(const CsgNode&)> count = [&](const CsgNode& n) {
    if (n.is_leaf) {
      leaves++;
      return;
    }
    count(*n.a);
    count(*n.b);
  };
  for (const Object& o : scene->objects)
    if (o.type == ObjectType::Csg) {
      objects++;
      count(*o.csg);
    }
  ASSERT_EQ(objects, 4u);
  SoftRasterizer r;
  RenderOptions options;
  options.mode = RenderMode::Full;
  Expected<RenderOutput> out = r.render(*scene, options);
  ASSERT_TRUE(out.ok());
  EXPECT_TRUE(out->warnings.empty()) << out->warnings.front();
  EXPECT_EQ(out->stats.at("csg.objects"), double(objects));
  EXPECT_EQ(out->stats.at("csg.leaf_passes"), double(2 * leaves));
  EXPECT_GT(out->stats.at("csg.pixels"), 0.0);
  EXPECT_GT(out->stats.at("shadows.cubes"), 0.0);
  size_t csg_pixels = 0;
  for (uint32_t id : out->buffers.object_id)
    csg_pixels += id != kNoId && scene->objects[id].type == ObjectType::Csg;
  EXPECT_EQ(double(csg_pixels), out->stats.at("csg.pixels"));
  EXPECT_EQ(r.name(), "softraster");
}

// pixels.covered is counted from the blocks' counts of empty pixels, not read pixel by pixel:
// it must equal the pixels with an id in the frame written, whatever drew them (the fill
// kernels of every instruction set, with and without hi-z, and the CSG pass's surfaces).
TEST(SoftRasterizer, PixelsCoveredIsThePixelsWithAnId) {
  std::vector<std::pair<std::string, Scene>> scenes;
  for (const char* name : {"tessphere:2000", "occluders:8", "soup:3000", "cornell", "csg"}) {
    Expected<Scene> scene = make_builtin_scene(name);
    ASSERT_TRUE(scene.ok());
    scenes.emplace_back(name, *scene);
  }
  // The CSG solids alone: their surfaces land on empty pixels, not on a wall drawn before.
  Scene solids = scenes.back().second;
  std::erase_if(solids.objects, [](const Object& o) { return o.type != ObjectType::Csg; });
  scenes.emplace_back("csg solids alone", solids);
  for (auto& [name, scene] : scenes) {
    scene.image.width = 203;  // blocks cut by the frame's right and bottom edges
    scene.image.height = 117;
    for (Isa isa : kAllIsas) {
      if (!cpu_supports(isa)) continue;
      for (bool hiz : {true, false}) {
        SoftRasterizer r;
        RenderOptions options;
        options.hiz = hiz;
        options.isa = isa;
        Expected<RenderOutput> out = r.render(scene, options);
        ASSERT_TRUE(out.ok()) << out.error().message;
        size_t with_id = 0;
        for (uint32_t id : out->buffers.object_id) with_id += id != kNoId;
        EXPECT_GT(with_id, 0u) << name;
        EXPECT_EQ(out->stats.at("pixels.covered"), double(with_id))
            << name << " " << to_string(isa) << " hiz " << hiz;
      }
    }
  }
}

// RenderOptions::zbuffer_left_out (the hybrids' z-buffer pass): both z-buffers draw the scene as
// if the objects left out had no triangles, and every other object keeps its id. The expected ids
// come from the same scene with those objects emptied (a mesh with no triangles, same index);
// each left-out object is seen in the full render first, so leaving out nothing fails.
TEST(ZBufferLeftOut, DrawsTheSceneAsIfTheObjectsHadNoTriangles) {
  for (const char* scene_name : {"cornell", "csg"}) {
    Scene scene = make_builtin_scene(scene_name).value();
    scene.image.width = 160;
    scene.image.height = 120;
    std::vector<uint32_t> left_out;
    Scene emptied = scene;
    for (uint32_t i = 0; i < scene.objects.size(); ++i) {
      const ObjectType type = scene.objects[i].type;
      if (type != ObjectType::Sphere && type != ObjectType::Disc && type != ObjectType::Csg)
        continue;
      left_out.push_back(i);
      emptied.objects[i] = Object{};
      emptied.objects[i].name = scene.objects[i].name;
      emptied.objects[i].material = scene.objects[i].material;
    }
    ASSERT_FALSE(left_out.empty()) << scene_name;
    for (const char* renderer_name : {"raster", "softraster"}) {
      SCOPED_TRACE(std::string(renderer_name) + " " + scene_name);
      std::unique_ptr<Renderer> renderer = make_renderer(renderer_name).value();
      RenderOptions options;
      options.mode = RenderMode::Visibility;
      const FrameBuffers all = renderer->render(scene, options).value().buffers;
      for (uint32_t object : left_out)
        EXPECT_NE(std::count(all.object_id.begin(), all.object_id.end(), object), 0)
            << "object " << object << " is seen when drawn";
      const FrameBuffers expected = renderer->render(emptied, options).value().buffers;
      options.zbuffer_left_out = left_out;
      const FrameBuffers got = renderer->render(scene, options).value().buffers;
      EXPECT_TRUE(test::same_bytes(got.object_id, expected.object_id));
      EXPECT_TRUE(test::same_bytes(got.primitive_id, expected.primitive_id));
      EXPECT_TRUE(test::same_bytes(got.depth, expected.depth));
    }
  }
}

}  // namespace
}  // namespace rvr
