// No NaN in any output of any renderer, whatever it is given: every built-in scene (csg too) in
// every mode, and a mesh of degenerate triangles and zero-length normals that the loader would
// have dropped or refused (a hand-built scene reaches the renderers without it).
#include <gtest/gtest.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <initializer_list>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"
#include "scene_builders.h"

using namespace rvr;

namespace {

// Degenerate triangles (zero area, collinear, repeated vertex) beside good ones, smooth with
// zero-length and opposite normals, so interpolated normals can cancel to zero.
Scene degenerate_mesh_scene() {
  Scene s = test::empty_scene(64, 48, {0, 0, 4}, {0, 0, 0}, 45.0f);
  s.lights.push_back(Light{LightType::Point, {1, 2, 3}, {}, {}, {}, glm::vec3(10.0f), 1});
  Object o;
  o.type = ObjectType::Triangles;
  o.name = "degenerate";
  TriangleMesh& m = o.mesh;
  m.positions = {{-1, -1, 0},     {1, -1, 0}, {0, 1, 0},   {0.5f, 0.5f, 0},
                 {0.5f, 0.5f, 0}, {2, 2, 0},  {-1, 1, -1}, {1, 1, -1}};
  m.normals = {{0, 0, 1}, {0, 0, -1}, {0, 0, 0}, {0, 0, 0},
               {0, 0, 0}, {0, 0, 0},  {0, 0, 1}, {0, 0, -1}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}, {3, 3, 3}, {0, 3, 5}, {6, 7, 2}, {0, 0, 1}};
  s.objects.push_back(o);
  return s;
}

void expect_no_nan(const FrameBuffers& fb, const std::string& what) {
  size_t bad = 0;
  for (size_t i = 0; i < fb.pixel_count(); ++i) {
    const glm::vec3 &c = fb.colour[i], &n = fb.normal[i];
    bool ok = std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) &&
              std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z) &&
              !std::isnan(fb.depth[i]) &&  // +inf is the background's depth, by the format
              std::isfinite(fb.cost[i]);
    bad += !ok;
  }
  EXPECT_EQ(bad, 0u) << what << ": pixels with NaN or infinite values";
}

}  // namespace

TEST(NoNan, AnyRendererAnySceneAnyMode) {
  std::vector<std::pair<std::string, Scene>> scenes;
  for (const BuiltinSceneInfo& b : builtin_scenes()) {
    std::string name = b.name;
    if (name.find(":N") != std::string::npos) name.replace(name.find(":N"), 2, ":300");
    Expected<Scene> s = make_builtin_scene(name);
    ASSERT_TRUE(s.ok()) << name;
    scenes.emplace_back(name, std::move(s).value());
  }
  scenes.emplace_back("degenerate mesh", degenerate_mesh_scene());
  for (auto& [name, scene] : scenes) {
    scene.image.width = 64;  // small: this is about values, not pictures
    scene.image.height = 48;
    scene.image.samples_per_pixel = std::min(scene.image.samples_per_pixel, 4);
    for (const RendererInfo& info : renderers()) {
      const std::string& r = info.name;
      for (RenderMode mode : {RenderMode::Visibility, RenderMode::Local, RenderMode::Full}) {
        auto renderer = info.create({});
        ASSERT_TRUE(renderer.ok());
        RenderOptions options;
        options.mode = mode;
        // Cube maps at a 64x48 frame's worth. GL's (llvmpipe: a whole pass per face, its
        // targets resized to the face) cost this test minutes; their values are held to the
        // tracer by test_environment_maps, so here only softraster draws them.
        options.cube_map_size = info.name.rfind("softraster", 0) == 0 ? 16 : 0;
        // Shadow maps at a 64x48 frame's worth too: at the default 1024 texels a side, each
        // light sample's six faces are 300 times the frame, and cornell's area light has 16
        // samples. The values are as finite at 64 (shadow agreement is test_shadow_agreement's).
        options.shadow_map_size = 64;
        // Coarse spheres: mirror_balls:300 draws every ball into six cube faces of each ball in
        // view, each at the default 64 longitudes 3968 triangles.
        options.sphere_segments = 16;
        for (SphereMode spheres : {SphereMode::Analytic, SphereMode::Mesh}) {
          options.spheres = spheres;
          Expected<RenderOutput> out = renderer.value()->render(scene, options);
          ASSERT_TRUE(out.ok()) << r << " " << name << ": " << out.error().message;
          expect_no_nan(out->buffers, r + " on " + name + " in mode " + std::to_string(int(mode)) +
                                          (spheres == SphereMode::Mesh ? ", mesh spheres" : ""));
        }
      }
    }
  }
}
