// The SIMD kernels (sse, avx2, avx512: each this CPU can run) of the tracer and of softraster, and
// thread counts, change nothing in what is rendered: every buffer, the cost AOV included, is the
// same bytes for every built-in scene in every mode, with analytic and tessellated spheres (the
// tracer) and with hierarchical z on and off (softraster). softraster's batched setup kernels
// also set up every triangle exactly as its scalar setup does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/isa.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/raster/soft_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/scene_io/scene_loader.h"
#include "same_bytes.h"
#include "soft/fill_dispatch.h"
#include "soft/fill_kernel.h"
#include "soft/setup_kernel.h"
#include "soft/setup_triangle.h"
#include "soft/triangle_setup.h"

using namespace rvr;

namespace {

using rvr::test::same_bytes;

// The first differing buffer, or "" when all are the same bytes.
std::string first_difference(const FrameBuffers& a, const FrameBuffers& b) {
  if (!same_bytes(a.object_id, b.object_id)) return "object id";
  if (!same_bytes(a.primitive_id, b.primitive_id)) return "primitive id";
  if (!same_bytes(a.depth, b.depth)) return "depth";
  if (!same_bytes(a.normal, b.normal)) return "normal";
  if (!same_bytes(a.colour, b.colour)) return "colour";
  if (!same_bytes(a.cost, b.cost)) return "cost";
  if (!same_bytes(a.answer, b.answer)) return "answer";
  return "";
}

RenderOutput render(const Scene& scene, RenderMode mode, SphereMode spheres, Isa isa, int threads) {
  RenderOptions options;
  options.mode = mode;
  options.spheres = spheres;
  options.sphere_segments = 24;
  options.isa = isa;
  options.threads = threads;
  RayTracer tracer;
  Expected<RenderOutput> out = tracer.render(scene, options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return out.ok() ? std::move(out).value() : RenderOutput{};
}

RenderOutput render_soft(const Scene& scene, RenderMode mode, bool hiz, Isa isa, int threads) {
  RenderOptions options;
  options.mode = mode;
  options.hiz = hiz;
  // Small maps keep cornell's 16 area-light cubes quick; the same kernels draw them.
  options.shadow_map_size = 128;
  // Cube faces of an odd size, like the image (rows end inside a SIMD group): at the default
  // 256, mirror_balls' 96 faces would be 800 times the image's pixels.
  options.cube_map_size = 37;
  options.isa = isa;
  options.threads = threads;
  SoftRasterizer rasterizer;
  Expected<RenderOutput> out = rasterizer.render(scene, options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return out.ok() ? std::move(out).value() : RenderOutput{};
}

std::vector<Isa> runnable_isas() {
  std::vector<Isa> isas;
  for (Isa isa : kAllIsas)
    if (cpu_supports(isa)) isas.push_back(isa);
  return isas;
}

class Kernels : public ::testing::TestWithParam<std::string> {};

}  // namespace

TEST_P(Kernels, EveryKernelAndThreadCountRendersTheSameBytes) {
  std::string name = GetParam();
  Expected<Scene> loaded = make_builtin_scene(name);
  ASSERT_TRUE(loaded.ok());
  Scene scene = *loaded;
  // Small, so the whole matrix runs in seconds; every feature of the scene is still drawn.
  scene.image.width = 96;
  scene.image.height = 72;
  std::vector<Isa> isas = runnable_isas();
  ASSERT_FALSE(isas.empty());
  for (RenderMode mode : {RenderMode::Visibility, RenderMode::Local, RenderMode::Full}) {
    for (SphereMode spheres : {SphereMode::Analytic, SphereMode::Mesh}) {
      RenderOutput reference = render(scene, mode, spheres, isas[0], 1);
      ASSERT_EQ(reference.info["kernel"], to_string(isas[0]));
      for (Isa isa : isas) {
        for (int threads : {1, 2}) {
          RenderOutput out = render(scene, mode, spheres, isa, threads);
          EXPECT_EQ(out.info["kernel"], to_string(isa));
          EXPECT_EQ(first_difference(reference.buffers, out.buffers), "")
              << name << " " << to_string(mode) << (spheres == SphereMode::Mesh ? " mesh" : "")
              << ": " << to_string(isa) << " on " << threads << " threads differs from "
              << to_string(isas[0]) << " on 1";
          for (const char* k : {"rays.primary", "rays.shadow", "rays.reflection", "rays.refraction",
                                "bvh.nodes_visited", "primitive_tests"})
            EXPECT_EQ(out.stats[k], reference.stats[k]) << name << " " << k;
        }
      }
    }
  }
}

TEST_P(Kernels, SoftrasterRendersTheSameBytesWithEveryKernelAndThreadCount) {
  std::string name = GetParam();
  Expected<Scene> loaded = make_builtin_scene(name);
  ASSERT_TRUE(loaded.ok());
  Scene scene = *loaded;
  // Odd sizes: rows end inside a SIMD group and inside an 8x8 block.
  scene.image.width = 101;
  scene.image.height = 75;
  std::vector<Isa> isas = runnable_isas();
  ASSERT_FALSE(isas.empty());
  for (RenderMode mode : {RenderMode::Visibility, RenderMode::Local, RenderMode::Full}) {
    for (bool hiz : {true, false}) {
      RenderOutput reference = render_soft(scene, mode, hiz, isas[0], 1);
      ASSERT_EQ(reference.info["kernel"], to_string(isas[0]));
      for (Isa isa : isas) {
        for (int threads : {1, 2}) {
          RenderOutput out = render_soft(scene, mode, hiz, isa, threads);
          EXPECT_EQ(out.info["kernel"], to_string(isa));
          EXPECT_EQ(first_difference(reference.buffers, out.buffers), "")
              << name << " " << to_string(mode) << (hiz ? "" : " no hi-z") << ": " << to_string(isa)
              << " on " << threads << " threads differs from " << to_string(isas[0]) << " on 1";
          for (const char* k : {"fragments.generated", "triangles.setup", "hiz.blocks_rejected"})
            EXPECT_EQ(out.stats[k], reference.stats[k]) << name << " " << k;
        }
      }
    }
  }
}

namespace {

// Every field, doubles bit for bit ("" when all agree).
std::string setup_difference(const soft::SetupTriangle& a, const soft::SetupTriangle& b) {
  auto same = [](const auto& x, const auto& y) { return std::memcmp(&x, &y, sizeof(x)) == 0; };
  if (!same(a.x, b.x) || !same(a.y, b.y)) return "fixed-point vertices";
  if (!same(a.top_left, b.top_left)) return "top-left edges";
  if (!same(a.q0, b.q0) || !same(a.qa, b.qa) || !same(a.qb, b.qb)) return "perspective planes";
  if (a.x0 != b.x0 || a.y0 != b.y0 || a.x1 != b.x1 || a.y1 != b.y1) return "pixel box";
  if (!same(a.min_depth, b.min_depth)) return "hi-z bound";
  if (a.object != b.object || a.primitive != b.primitive) return "ids";
  return "";
}

// A setup batch's vertices in SoA, filled from TriangleSetup::project's results.
struct BatchVertices {
  std::vector<int32_t> fx, fy;
  std::vector<double> sx, sy, w, inv_w;
  explicit BatchVertices(size_t n) : fx(n), fy(n), sx(n), sy(n), w(n), inv_w(n) {}
  void set(size_t i, const soft::ProjectedVertex& p) {
    fx[i] = int32_t(p.fx);
    fy[i] = int32_t(p.fy);
    sx[i] = p.sx;
    sy[i] = p.sy;
    w[i] = p.clip.w;
    inv_w[i] = p.inv_w;
  }
  soft::VertexArrays arrays() {
    return {fx.data(), fy.data(), sx.data(), sy.data(), w.data(), inv_w.data()};
  }
};

// A width x height frame seen through a 0.9-radian perspective from the origin, looking down
// -z, with softraster's setup for it, and the random draws the tests place triangles with.
struct RandomFrame {
  RandomFrame(int w, int h, unsigned seed, float nearest, float farthest)
      : width(w),
        height(h),
        setup(w, h, glm::dmat4(glm::perspective(0.9f, float(w) / float(h), 0.1f, 500.0f))),
        rng(seed),
        log_depth(std::log(nearest), std::log(farthest)) {}
  float unit() { return unit_draw(rng); }             // uniform in [-1, 1]
  float depth() { return std::exp(log_depth(rng)); }  // log-uniform in [nearest, farthest]
  int width, height;
  soft::TriangleSetup setup;
  std::mt19937 rng;
  std::uniform_real_distribution<float> unit_draw{-1.0f, 1.0f};
  std::uniform_real_distribution<float> log_depth;
};

// `count` random triangles, three vertices each as `setup` projects them: `corners(p)` places a
// triangle's points; one that needs clipping, lies wholly outside the view or that `keep`
// refuses is placed again.
template <class Corners, class Keep>
std::vector<soft::ProjectedVertex> projected_triangles(const soft::TriangleSetup& setup,
                                                       size_t count, Corners&& corners,
                                                       Keep&& keep) {
  std::vector<soft::ProjectedVertex> vertices;
  while (vertices.size() < 3 * count) {
    glm::vec3 p[3];
    corners(p);
    const soft::ProjectedVertex v[3] = {setup.project(p[0]), setup.project(p[1]),
                                        setup.project(p[2])};
    if (v[0].clip_planes | v[1].clip_planes | v[2].clip_planes) continue;
    if ((v[0].reject & v[1].reject & v[2].reject) || !keep(v)) continue;
    vertices.insert(vertices.end(), v, v + 3);
  }
  return vertices;
}

}  // namespace

// The batched setup kernels against TriangleSetup::add, the scalar setup (the oracle: the code
// softraster used before the kernels, still used for clipped triangles), on random triangles
// that need no clipping: sub-pixel ones (most hold no centre), a few pixels (the small-box
// coverage test), large ones, slivers, degenerate ones (repeated or collinear vertices), both
// windings, depths from 0.2 to 200.
TEST(SoftrasterSetup, EveryKernelSetsUpTrianglesAsTheScalarSetupDoes) {
  RandomFrame frame(101, 75, 12, 0.2f, 200.0f);
  const int width = frame.width, height = frame.height;
  const soft::TriangleSetup& scalar = frame.setup;
  std::uniform_int_distribution<int> kind(0, 5);
  auto corners = [&](glm::vec3(&p)[3]) {
    const float z = -frame.depth();
    const float cx = frame.unit() * -z * 0.6f, cy = frame.unit() * -z * 0.45f;
    const glm::vec3 centre(cx, cy, z);
    // Pixels are about |z| / 100 wide here.
    const float sizes[6] = {0.003f, 0.01f, 0.03f, 0.3f, 0.01f, 0.01f};
    const int k = kind(frame.rng);
    const float s = sizes[k] * -z;
    for (glm::vec3& v : p) {
      const float dx = frame.unit(), dy = frame.unit(), dz = frame.unit();
      v = centre + s * glm::vec3(dx, dy, dz * 0.1f);
    }
    if (k == 4) p[2] = p[0];                          // two vertices the same
    if (k == 5) p[2] = p[0] + 0.37f * (p[1] - p[0]);  // collinear
  };
  const std::vector<soft::ProjectedVertex> vertices = projected_triangles(
      scalar, 20000, corners, [](const soft::ProjectedVertex*) { return true; });
  const size_t count = vertices.size() / 3;
  soft::TriangleSetup reference_setup = scalar;
  soft::SetupTriangles expected;
  size_t clipped = 0;
  for (size_t i = 0; i < count; ++i)
    reference_setup.add(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2], 7, uint32_t(i),
                        expected, clipped);
  ASSERT_EQ(clipped, 0u);
  // The sample reaches every branch of the setup: dropped and kept, small and large boxes.
  ASSERT_GT(expected.size(), count / 10);
  ASSERT_LT(expected.size(), count * 9 / 10);
  for (Isa isa : runnable_isas()) {
    const soft::FillKernels& kernels = soft::fill_kernels(isa);
    std::vector<soft::SetupTriangle> got(count);
    BatchVertices all(vertices.size());
    const size_t last = vertices.size() - 1;
    for (size_t i = 0; i < vertices.size(); ++i) all.set(last - i, vertices[i]);
    size_t n = 0;
    // Batches of every fill from 1 to kSetupBatch, so partial vectors are exercised; corners
    // listed in reverse order, so a kernel must follow the indices.
    for (size_t i = 0, fill = 1; i < count; fill = fill % soft::kSetupBatch + 1) {
      soft::SetupBatch batch;
      batch.vertices = all.arrays();
      for (; batch.count < int(fill) && i < count; ++i, ++batch.count) {
        const int k = batch.count;
        for (int v = 0; v < 3; ++v) batch.vertex[v][k] = uint32_t(last - (3 * i + size_t(v)));
        batch.object[k] = 7;
        batch.primitive[k] = uint32_t(i);
      }
      n += size_t(kernels.setup(batch, width, height, got.data() + n));
    }
    ASSERT_EQ(n, expected.size()) << kernels.isa;
    for (size_t i = 0; i < n; ++i)
      ASSERT_EQ(setup_difference(got[i], expected[i]), "")
          << kernels.isa << ": set-up triangle " << i << " (input " << expected[i].primitive << ")";
  }
}

// The perspective planes against their closed form: at the unsnapped screen position of the
// original triangle's vertex k, plane j is (barycentric j of that point) / w = (j == k) / w_k,
// whatever origin setup stores the planes at. Scalar setup and every kernel, on random triangles
// of one pixel to a quarter of the frame, both windings, depths 0.5 to 50. Evaluated without
// the clamp; the tolerance is 1e-10 of the largest 1/w_k: the evaluation's rounding is a few
// ulps of terms no larger than 1/w_k times the triangles' modest slope ratios, while a plane
// stored at a point other than the one its origin is read from (a sub-pixel step, 1/8192 pixel)
// is off by its slope over that step, 1e-7 of 1/w_k or more.
TEST(SoftrasterSetup, PlanesAreBarycentricsOverDepthAtTheVertices) {
  RandomFrame frame(160, 120, 31, 0.5f, 50.0f);
  const int width = frame.width, height = frame.height;
  std::uniform_real_distribution<float> log_size(std::log(0.01f), std::log(0.3f));
  auto corners = [&](glm::vec3(&p)[3]) {
    const float z = -frame.depth();
    const float cx = frame.unit() * -z * 0.5f, cy = frame.unit() * -z * 0.35f;
    const glm::vec3 centre(cx, cy, z);
    const float s = std::exp(log_size(frame.rng)) * -z;  // pixels are about |z| / 160 wide
    for (glm::vec3& v : p) {
      const float dx = frame.unit(), dy = frame.unit(), dz = frame.unit();
      v = centre + s * glm::vec3(dx, dy, dz * 0.5f);
    }
  };
  // Wholly on screen and well conditioned: the smallest altitude at least a tenth of the
  // longest side.
  auto well_conditioned = [](const soft::ProjectedVertex* v) {
    if (v[0].reject | v[1].reject | v[2].reject) return false;
    const double ax = v[1].sx - v[0].sx, ay = v[1].sy - v[0].sy;
    const double bx = v[2].sx - v[0].sx, by = v[2].sy - v[0].sy;
    const double cx = v[2].sx - v[1].sx, cy = v[2].sy - v[1].sy;
    const double longest2 = std::max({ax * ax + ay * ay, bx * bx + by * by, cx * cx + cy * cy});
    return std::abs(ax * by - bx * ay) >= 0.1 * longest2;
  };
  const std::vector<soft::ProjectedVertex> vertices =
      projected_triangles(frame.setup, 3000, corners, well_conditioned);
  const size_t count = vertices.size() / 3;
  auto check = [&](const soft::SetupTriangle& t, const std::string& who) {
    const size_t i = t.primitive;
    const soft::ProjectedVertex* v = &vertices[3 * i];
    const double scale = std::max({v[0].inv_w, v[1].inv_w, v[2].inv_w});
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) {
        const double q = t.q0[j] + t.qa[j] * (v[k].sx - t.ox()) + t.qb[j] * (v[k].sy - t.oy());
        const double expected = j == k ? v[k].inv_w : 0.0;
        ASSERT_NEAR(q, expected, 1e-10 * scale)
            << who << ": triangle " << i << ", plane " << j << " at vertex " << k;
      }
  };
  soft::TriangleSetup reference_setup = frame.setup;
  soft::SetupTriangles expected;
  size_t clipped = 0;
  for (size_t i = 0; i < count; ++i)
    reference_setup.add(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2], 7, uint32_t(i),
                        expected, clipped);
  ASSERT_GT(expected.size(), count / 2);
  for (const soft::SetupTriangle& t : expected) check(t, "scalar setup");
  for (Isa isa : runnable_isas()) {
    const soft::FillKernels& kernels = soft::fill_kernels(isa);
    BatchVertices all(vertices.size());
    for (size_t i = 0; i < vertices.size(); ++i) all.set(i, vertices[i]);
    std::vector<soft::SetupTriangle> got(soft::kSetupBatch);
    size_t n = 0;
    for (size_t i = 0; i < count;) {
      soft::SetupBatch batch;
      batch.vertices = all.arrays();
      for (; batch.count < soft::kSetupBatch && i < count; ++i, ++batch.count) {
        for (int v = 0; v < 3; ++v) batch.vertex[v][batch.count] = uint32_t(3 * i + size_t(v));
        batch.object[batch.count] = 7;
        batch.primitive[batch.count] = uint32_t(i);
      }
      const int kept = kernels.setup(batch, width, height, got.data());
      for (int k = 0; k < kept; ++k) check(got[size_t(k)], kernels.isa);
      n += size_t(kept);
    }
    EXPECT_EQ(n, expected.size()) << kernels.isa;
  }
}

// The projection kernels against TriangleSetup::project, bit for bit, on points everywhere:
// inside the view, outside each frustum plane, behind the eye, across the guard band and just
// inside it, on the eye plane (w = 0), and non-finite ones (which must be left to the scalar
// path: kScalarOnly).
TEST(SoftrasterSetup, EveryProjectionKernelProjectsAsTriangleSetupDoes) {
  const int width = 1024, height = 768;
  const glm::dmat4 view_projection =
      glm::dmat4(glm::perspective(0.9f, float(width) / float(height), 0.1f, 500.0f)) *
      glm::dmat4(glm::lookAt(glm::vec3(0.3f, 0.2f, 4.0f), glm::vec3(0.0f), glm::vec3(0, 1, 0)));
  const soft::TriangleSetup scalar(width, height, view_projection);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_real_distribution<float> log_scale(std::log(1e-3f), std::log(1e5f));
  std::vector<glm::vec3> points;
  for (int i = 0; i < 50000; ++i) {
    const float s = std::exp(log_scale(rng));
    points.push_back(s * glm::vec3(unit(rng), unit(rng), unit(rng)));
  }
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  points.push_back({0.3f, 0.2f, 4.0f});  // the eye
  points.push_back({nan, 0.0f, 0.0f});
  points.push_back({0.0f, inf, 0.0f});
  points.push_back({-inf, 0.0f, -inf});
  const size_t n = points.size();
  size_t unclipped = 0, scalar_only = 0;
  for (Isa isa : runnable_isas()) {
    const soft::FillKernels& kernels = soft::fill_kernels(isa);
    BatchVertices got(n);
    std::vector<uint8_t> reject(n), clip(n);
    soft::ProjectionParams params{};
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) params.m[c][r] = view_projection[c][r];
    params.width = width;
    params.height = height;
    params.gx = soft::kGuardPixels / width;
    params.gy = soft::kGuardPixels / height;
    kernels.project(params, &points[0].x, n, {got.arrays(), reject.data(), clip.data()});
    unclipped = scalar_only = 0;
    for (size_t i = 0; i < n; ++i) {
      const soft::ProjectedVertex e = scalar.project(points[i]);
      ASSERT_EQ(reject[i], e.reject) << kernels.isa << ": point " << i;
      ASSERT_EQ(clip[i] & ~soft::kScalarOnly, e.clip_planes) << kernels.isa << ": point " << i;
      if (e.clip_planes != 0) continue;
      const bool finite = std::isfinite(e.sx) && std::isfinite(e.sy);
      ASSERT_EQ((clip[i] & soft::kScalarOnly) != 0, !finite) << kernels.isa << ": point " << i;
      if (!finite) {
        ++scalar_only;
        continue;
      }
      ++unclipped;
      auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
      ASSERT_EQ(got.fx[i], e.fx) << kernels.isa << ": point " << i;
      ASSERT_EQ(got.fy[i], e.fy) << kernels.isa << ": point " << i;
      ASSERT_TRUE(same(got.sx[i], e.sx) && same(got.sy[i], e.sy)) << kernels.isa << ": " << i;
      ASSERT_TRUE(same(got.w[i], e.clip.w) && same(got.inv_w[i], e.inv_w)) << kernels.isa;
    }
  }
  // The sample reaches both sides of the clip test and the non-finite case.
  EXPECT_GT(unclipped, n / 10);
  EXPECT_LT(unclipped, n * 9 / 10);
  EXPECT_GT(scalar_only, 0u);
}

// A vertex whose projection is not finite (a coordinate the projection overflows, or NaN) has no
// screen position: a triangle with one is dropped and counted as clipped, whichever of the
// scalar paths (unclipped, or crossing the near plane) it would otherwise take. Its neighbours
// made of finite vertices are set up as usual.
TEST(SoftrasterSetup, TrianglesWithANonFiniteVertexAreDropped) {
  const int width = 64, height = 48;
  const glm::dmat4 view_projection =
      glm::dmat4(glm::perspective(0.9f, float(width) / float(height), 0.1f, 500.0f)) *
      glm::dmat4(glm::lookAt(glm::vec3(0.0f, 0.0f, 4.0f), glm::vec3(0.0f), glm::vec3(0, 1, 0)));
  soft::TriangleSetup setup(width, height, view_projection);
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const soft::ProjectedVertex a = setup.project({-1, -1, 0}), b = setup.project({1, -1, 0});
  const soft::ProjectedVertex c = setup.project({0, 1, 0});
  const soft::ProjectedVertex behind = setup.project({0, 1, 10});  // behind the eye: clipped
  ASSERT_EQ(a.clip_planes | b.clip_planes | c.clip_planes, 0u);
  ASSERT_NE(behind.clip_planes, 0u);
  soft::SetupTriangles out;
  size_t clipped = 0;
  setup.add(a, b, c, 0, 0, out, clipped);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(clipped, 0u);
  setup.add(a, b, behind, 0, 1, out, clipped);  // clipped, and something remains
  ASSERT_GT(out.size(), 1u);
  ASSERT_EQ(clipped, 1u);
  const size_t before = out.size();
  for (const glm::vec3 bad : {glm::vec3(nan, 0, 0), glm::vec3(inf, 1, 0), glm::vec3(0, -inf, 0),
                              glm::vec3(inf, inf, inf), glm::vec3(0, 0, -inf)}) {
    const soft::ProjectedVertex v = setup.project(bad);
    clipped = 0;
    setup.add(a, b, v, 0, 2, out, clipped);
    setup.add(v, behind, c, 0, 3, out, clipped);
    EXPECT_EQ(out.size(), before) << bad.x << " " << bad.y << " " << bad.z;
    EXPECT_EQ(clipped, 2u);
  }
}

// SetupTriangle keeps fixed-point vertices in 32 bits: enough for anything inside the guard band
// (clipping keeps screen positions within kGuardPixels / 2 + width / 2 pixels). A triangle
// reaching far left is clipped at the guard plane (scalar path); one reaching just inside it is
// not (the setup kernels). Their stored x must be the fixed-point value the screen position
// gives, computed here from the guard band's definition (the clip and the division may move a
// clipped vertex by rounding: one sub-pixel of slack, far below any truncation's error).
TEST(SoftrasterSetup, FixedPointVerticesAtTheGuardBandAreStoredExactly) {
  const int width = 1024, height = 768;
  // clip = (x / 3, y, z, 1): a third is no binary fraction, so positions are not round numbers
  // that a narrower type (a float's 24 bits) would happen to hold exactly.
  glm::dmat4 view_projection(1.0);
  view_projection[0][0] = 1.0 / 3.0;
  const soft::TriangleSetup setup(width, height, view_projection);
  const double guard_ndc = soft::kGuardPixels / width;
  // The sub-pixel that world x snaps to (the projection's operations, in its order).
  auto fixed_x = [&](float x) {
    const double ndc = (1.0 / 3.0) * double(x);
    return std::llround((ndc * 0.5 + 0.5) * width * double(soft::kSub));
  };
  const int64_t at_guard = std::llround((-guard_ndc * 0.5 + 0.5) * width * double(soft::kSub));
  ASSERT_LT(at_guard, -(int64_t(1) << 26));  // far beyond 16 bits: the test can see truncation

  // Clipped: vertex A at NDC x = -40 guard widths (x = -120 guard widths); the clipped vertices lie
  // on x = -guard.
  {
    soft::TriangleSetup clipper = setup;
    soft::SetupTriangles out;
    size_t clipped = 0;
    clipper.add(setup.project({-120.0f * float(guard_ndc), -0.5f, 0.0f}),
                setup.project({2.7f, 0.9f, 0.0f}), setup.project({2.7f, -0.9f, 0.0f}), 1, 0, out,
                clipped);
    ASSERT_EQ(clipped, 1u);
    ASSERT_FALSE(out.empty());
    const int64_t right = fixed_x(2.7f);
    int at_the_guard = 0;
    for (const soft::SetupTriangle& t : out)
      for (int64_t x : t.x) {
        const bool on_guard = std::abs(x - at_guard) <= 1, on_right = x == right;
        EXPECT_TRUE(on_guard || on_right) << x << " is neither " << at_guard << " nor " << right;
        at_the_guard += on_guard;
      }
    EXPECT_GT(at_the_guard, 0);
  }
  // Unclipped, through every setup kernel: vertex A just inside the guard plane.
  const float inside = -2.997f * float(guard_ndc);
  const glm::vec3 p[3] = {{inside, 0.0f, 0.0f}, {2.7f, 0.9f, 0.0f}, {2.7f, -0.9f, 0.0f}};
  soft::SetupBatch batch;
  batch.count = 1;
  BatchVertices corners(3);
  batch.vertices = corners.arrays();
  for (int v = 0; v < 3; ++v) {
    const soft::ProjectedVertex pv = setup.project(p[v]);
    ASSERT_EQ(pv.clip_planes, 0u);
    corners.set(size_t(v), pv);
    batch.vertex[v][0] = uint32_t(v);
  }
  batch.object[0] = 1;
  batch.primitive[0] = 0;
  for (Isa isa : runnable_isas()) {
    const soft::FillKernels& kernels = soft::fill_kernels(isa);
    soft::SetupTriangle t;
    ASSERT_EQ(kernels.setup(batch, width, height, &t), 1) << kernels.isa;
    EXPECT_EQ(t.x[0], fixed_x(inside)) << kernels.isa;
    EXPECT_EQ(t.x[1], fixed_x(2.7f)) << kernels.isa;
    EXPECT_EQ(t.x[2], fixed_x(2.7f)) << kernels.isa;
  }
}

INSTANTIATE_TEST_SUITE_P(EveryBuiltinScene, Kernels, ::testing::ValuesIn([] {
                           std::vector<std::string> names;
                           for (const BuiltinSceneInfo& b : builtin_scenes())
                             names.push_back(b.name.substr(0, b.name.find(':')));
                           return names;
                         }()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

// RVR_ISA's decision on CPUs this machine may not be: every outcome, whatever runs the test
// (the CLI test covers the message's path to the user only on a CPU without AVX-512).
TEST(IsaSelection, ForcedKernelsTheCpuCannotRunAreBadInputNamingTheBest) {
  auto up_to = [](Isa widest) { return [widest](Isa isa) { return int(isa) <= int(widest); }; };
  for (Isa widest : kAllIsas) {
    EXPECT_EQ(select_isa(nullptr, up_to(widest)).value(), widest);
    EXPECT_EQ(select_isa("", up_to(widest)).value(), widest);
    for (Isa forced : kAllIsas) {
      Expected<Isa> got = select_isa(to_string(forced), up_to(widest));
      if (int(forced) <= int(widest)) {
        ASSERT_TRUE(got.ok()) << to_string(forced) << " on " << to_string(widest);
        EXPECT_EQ(*got, forced);
        continue;
      }
      ASSERT_FALSE(got.ok()) << to_string(forced) << " on " << to_string(widest);
      EXPECT_EQ(got.error().kind, ErrorKind::BadInput);
      EXPECT_EQ(got.error().message, std::string("RVR_ISA=") + to_string(forced) +
                                         ": this CPU cannot run " + to_string(forced) +
                                         " kernels (best available: " + to_string(widest) + ")");
    }
  }
  Expected<Isa> unknown = select_isa("avx3", up_to(Isa::Avx512));
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().message, "RVR_ISA=avx3: unknown (use sse, avx2 or avx512)");
}
