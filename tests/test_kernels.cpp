// The SIMD kernels (sse, avx2, avx512: each this CPU can run) of the tracer and of softraster, and
// thread counts, change nothing in what is rendered: every buffer, the cost AOV included, is the
// same bytes for every built-in scene in every mode, with analytic and tessellated spheres (the
// tracer) and with hierarchical z on and off (softraster).
#include <gtest/gtest.h>

#include <cstring>

#include "rvr/raster/soft_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/shared/scene_loader.h"

using namespace rvr;

namespace {

template <class T>
bool same_bytes(const PixelVector<T>& a, const PixelVector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// The first differing buffer, or "" when all are the same bytes.
std::string first_difference(const FrameBuffers& a, const FrameBuffers& b) {
  if (!same_bytes(a.object_id, b.object_id)) return "object id";
  if (!same_bytes(a.primitive_id, b.primitive_id)) return "primitive id";
  if (!same_bytes(a.depth, b.depth)) return "depth";
  if (!same_bytes(a.normal, b.normal)) return "normal";
  if (!same_bytes(a.color, b.color)) return "colour";
  if (!same_bytes(a.cost, b.cost)) return "cost";
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
  options.isa = isa;
  options.threads = threads;
  SoftRasterizer rasterizer;
  Expected<RenderOutput> out = rasterizer.render(scene, options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return out.ok() ? std::move(out).value() : RenderOutput{};
}

std::vector<Isa> runnable_isas() {
  std::vector<Isa> isas;
  for (Isa isa : {Isa::Sse, Isa::Avx2, Isa::Avx512})
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

INSTANTIATE_TEST_SUITE_P(EveryBuiltinScene, Kernels, ::testing::ValuesIn([] {
                           std::vector<std::string> names;
                           for (const BuiltinSceneInfo& b : builtin_scenes())
                             names.push_back(b.name.substr(0, b.name.find(':')));
                           return names;
                         }()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });
