// The tracer's images checked against geometry worked out by hand: shadows, mirrors, CSG,
// and the same bytes whatever the thread count.
#include <gtest/gtest.h>
#include <stdint.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/core/camera.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/isa.h"
#include "rvr/core/ray.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shading.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/raytrace/primary_rays.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh_layout.h"
#include "rvr/scene_io/scene_loader.h"
#include "scene_builders.h"

using namespace rvr;
using namespace rvr::test;

namespace {

RenderOutput trace(const Scene& s, RenderMode mode, int threads = 0) {
  RayTracer tracer;
  RenderOptions o;
  o.mode = mode;
  o.threads = threads;
  Expected<RenderOutput> out = tracer.render(s, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return std::move(out).value();
}

// Pixels whose analytic class differs from a 4-neighbour's: the boundary, where a pixel
// centre may fall either way by rounding.
std::vector<bool> class_boundary(const std::vector<int>& cls, int w, int h) {
  std::vector<bool> b(cls.size(), false);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int c = cls[y * w + x];
      if ((x > 0 && cls[y * w + x - 1] != c) || (x + 1 < w && cls[y * w + x + 1] != c) ||
          (y > 0 && cls[(y - 1) * w + x] != c) || (y + 1 < h && cls[(y + 1) * w + x] != c))
        b[y * w + x] = true;
    }
  return b;
}

}  // namespace

TEST(Tracer, SameBytesWithOneAndTwoThreads) {
  Expected<Scene> scene = make_builtin_scene("cornell");
  ASSERT_TRUE(scene.ok());
  Scene s = *scene;
  s.image.width = 160;
  s.image.height = 120;
  s.image.samples_per_pixel = 4;
  RenderOutput one = trace(s, RenderMode::Full, 1);
  RenderOutput two = trace(s, RenderMode::Full, 2);
  ASSERT_EQ(one.buffers.colour.size(), two.buffers.colour.size());
  EXPECT_EQ(std::memcmp(one.buffers.colour.data(), two.buffers.colour.data(),
                        one.buffers.colour.size() * sizeof(glm::vec3)),
            0);
  EXPECT_EQ(one.buffers.object_id, two.buffers.object_id);
  EXPECT_EQ(one.buffers.cost, two.buffers.cost);
  EXPECT_EQ(one.stats.at("rays.shadow"), two.stats.at("rays.shadow"));
}

// The cost AOV gives each pixel the traversal work of every ray traced for it: its centre ray,
// and in full mode its shadow, reflection and refraction rays and its further samples. Summed over
// the image it is the frame's counted work, which the tracer adds up separately (per block, in
// each thread's counters). Every count is far below 2^24, so each pixel's float is exact.
TEST(Tracer, CostAovAddsUpToTheFramesTraversalWork) {
  struct Case {
    const char* scene;
    RenderMode mode;
    int samples;
  };
  for (const Case c : {Case{"cornell", RenderMode::Visibility, 1},
                       Case{"cornell", RenderMode::Local, 1}, Case{"glass", RenderMode::Full, 1},
                       Case{"cornell", RenderMode::Full, 4}, Case{"csg", RenderMode::Local, 1}}) {
    Scene s = make_builtin_scene(c.scene).value();
    s.image.width = 96;
    s.image.height = 72;
    s.image.samples_per_pixel = c.samples;
    RenderOptions o;
    o.mode = c.mode;
    o.cost_aov = true;
    const RenderOutput out = RayTracer().render(s, o).value();
    double cost = 0.0;
    for (float v : out.buffers.cost) cost += double(v);
    const double counted = out.stats.at("bvh.nodes_visited") + out.stats.at("primitive_tests");
    const std::string name = std::string(c.scene) + " " + to_string(c.mode);
    EXPECT_GT(counted, 0.0) << name;
    EXPECT_EQ(cost, counted) << name;
  }
}

// The frame's time divides into visibility (until the primary hits are known) and shading, in
// the shares the threads' time divides (counted in time-stamp ticks): the two add up to the
// render time, and full shading with 4 samples a pixel, each traced with its shadow rays, takes
// a larger share than writing the AOVs of visibility mode. The margin is wide: visibility mode's
// share is its AOV writes beside the traversal, full mode's nearly all of the frame.
TEST(Tracer, RenderTimeSplitsIntoVisibilityAndShading) {
  Scene s = make_builtin_scene("cornell").value();
  s.image.width = 160;
  s.image.height = 120;
  auto share = [&](RenderMode mode, int samples) {
    s.image.samples_per_pixel = samples;
    RenderOptions o;
    o.mode = mode;
    const RenderOutput out = RayTracer().render(s, o).value();
    const double visibility = out.stats.at("time.visibility"), shade = out.stats.at("time.shade");
    EXPECT_GE(visibility, 0.0);
    EXPECT_GE(shade, 0.0);
    EXPECT_NEAR(visibility + shade, out.stats.at("time.render"), 1e-12);
    return shade / out.stats.at("time.render");
  };
  const double visibility_share = share(RenderMode::Visibility, 1);
  const double full_share = share(RenderMode::Full, 4);
  EXPECT_GT(full_share, 0.5);
  EXPECT_GT(full_share, visibility_share + 0.2);
}

// A sphere over a plane, a point light: a plane point is in shadow exactly when the segment
// to the light passes through the sphere. With no ambient light, shadowed plane pixels are 0.
TEST(Tracer, HardShadowIsTheProjectedSphere) {
  Scene s = empty_scene(200, 150, {0, 3, 4}, {0, 0, 0}, 50);
  uint32_t white = add_material(s, glm::vec3(0.8f));
  add_plane(s, {0, 0, 0}, {0, 1, 0}, 6, white);
  const Sphere ball{{0.2f, 0.8f, 0.1f}, 0.5f};
  add_sphere(s, ball.center, ball.radius, white);
  const glm::vec3 light(1.0f, 3.0f, 0.5f);
  s.lights.push_back({LightType::Point, light, {}, {}, {}, glm::vec3(10.0f), 1});
  RenderOutput out = trace(s, RenderMode::Full);
  const FrameBuffers& fb = out.buffers;
  CameraFrame frame = make_camera_frame(s.camera, s.image.width, s.image.height);

  const int w = s.image.width, h = s.image.height;
  std::vector<int> expected(size_t(w * h), -1);  // -1 not plane, 0 lit, 1 shadow
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      size_t i = fb.index(x, y);
      if (fb.object_id[i] != 0) continue;
      glm::vec3 p = s.camera.eye + fb.depth[i] * camera_ray_direction(frame, x + 0.5f, y + 0.5f);
      // Does the segment p -> light come within the radius of the centre?
      glm::vec3 d = light - p;
      float t = glm::clamp(glm::dot(ball.center - p, d) / glm::dot(d, d), 0.0f, 1.0f);
      expected[i] = glm::distance(p + t * d, ball.center) < ball.radius ? 1 : 0;
    }
  std::vector<bool> boundary = class_boundary(expected, w, h);
  size_t shadow = 0, compared = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    if (expected[i] < 0 || boundary[i]) continue;
    ++compared;
    bool dark = fb.colour[i] == glm::vec3(0.0f);
    EXPECT_EQ(dark, expected[i] == 1) << "pixel " << i % w << "," << i / w;
    shadow += expected[i];
  }
  EXPECT_GT(shadow, 500u);  // the shadow is really in view
  EXPECT_GT(compared, size_t(w * h / 2));
}

// A perfect mirror on z = 0 and an emissive red quad beside the camera, outside its view: the
// red shows where the ray to the quad's mirror image (at z -> -z) crosses the mirror.
TEST(Tracer, MirrorShowsTheQuadWhereReflectionGeometryPredicts) {
  Scene s = empty_scene(160, 120, {0, 0, 3}, {0, 0, 0}, 40);
  uint32_t mirror = add_material(s, glm::vec3(0.0f), glm::vec3(0.0f), 1.0f);
  uint32_t red = add_material(s, glm::vec3(0.0f), glm::vec3(1, 0, 0));
  const float mirror_half = 1.0f;
  add_plane(s, {0, 0, 0}, {0, 0, 1}, mirror_half, mirror);
  const glm::vec3 quad_centre(0.9f, 0.1f, 2.0f);
  const float quad_half = 0.3f;
  add_plane(s, quad_centre, {0, 0, -1}, quad_half, red);
  RenderOutput out = trace(s, RenderMode::Full);
  const FrameBuffers& fb = out.buffers;
  CameraFrame frame = make_camera_frame(s.camera, s.image.width, s.image.height);
  auto [qu, qv] = std::array<glm::vec3, 2>{glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};

  const int w = s.image.width, h = s.image.height;
  std::vector<int> expected(size_t(w * h), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 d = camera_ray_direction(frame, x + 0.5f, y + 0.5f);
      glm::vec3 o = s.camera.eye;
      float t_mirror = -o.z / d.z;
      glm::vec3 m = o + t_mirror * d;
      bool on_mirror = std::abs(m.x) <= mirror_half && std::abs(m.y) <= mirror_half;
      // The quad's image sits at z = -2; the ray reaches it after crossing the mirror.
      float t_image = (-quad_centre.z - o.z) / d.z;
      glm::vec3 q = o + t_image * d - glm::vec3(quad_centre.x, quad_centre.y, -quad_centre.z);
      bool on_image =
          std::abs(glm::dot(q, qu)) <= quad_half && std::abs(glm::dot(q, qv)) <= quad_half;
      expected[y * w + x] = on_mirror && on_image;
    }
  std::vector<bool> boundary = class_boundary(expected, w, h);
  size_t red_pixels = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    if (boundary[i]) continue;
    if (expected[i]) {
      ++red_pixels;
      EXPECT_EQ(fb.colour[i], glm::vec3(1, 0, 0)) << "pixel " << i % w << "," << i / w;
    } else {
      EXPECT_NE(fb.colour[i], glm::vec3(1, 0, 0)) << "pixel " << i % w << "," << i / w;
    }
  }
  EXPECT_GT(red_pixels, 200u);
  EXPECT_GT(out.stats.at("rays.reflection"), 0.0);
}

namespace {
std::shared_ptr<CsgNode> csg_leaf(glm::vec3 c, float r) {
  auto n = std::make_shared<CsgNode>();
  n->sphere = {c, r};
  return n;
}
std::shared_ptr<CsgNode> csg_op(CsgOp op, std::shared_ptr<CsgNode> a, std::shared_ptr<CsgNode> b) {
  auto n = std::make_shared<CsgNode>();
  n->is_leaf = false;
  n->op = op;
  n->a = a;
  n->b = b;
  return n;
}
}  // namespace

// A sphere minus a sphere biting its front: looking straight at the bite, the ray enters the
// big sphere inside the small one and meets the small sphere's far wall, an inner surface
// whose normal must face the viewer (and so be lit by a light at the eye).
TEST(Tracer, CsgDifferenceShowsTheBiteWithInnerSurfacesFacingTheViewer) {
  Scene s = empty_scene(101, 101, {0, 0, 5}, {0, 0, 0}, 30);
  Object o;
  o.type = ObjectType::Csg;
  o.csg = csg_op(CsgOp::Difference, csg_leaf({0, 0, 0}, 1.0f), csg_leaf({0, 0, 1}, 0.6f));
  s.objects.push_back(o);
  s.lights.push_back({LightType::Point, {0, 0, 5}, {}, {}, {}, glm::vec3(20.0f), 1});
  RenderOutput out = trace(s, RenderMode::Full);
  const FrameBuffers& fb = out.buffers;
  size_t centre = fb.index(50, 50);
  ASSERT_EQ(fb.object_id[centre], 0u);
  EXPECT_NEAR(fb.depth[centre], 5.0f - 0.4f, 1e-4f);  // the bite's bottom at z = 0.4
  EXPECT_GT(fb.normal[centre].z, 0.99f);
  EXPECT_GT(fb.colour[centre].x, 0.1f);  // lit: the inner wall faces the light at the eye
  // Away from the bite, the big sphere's own front: at the pixel row through y = 0.8 the
  // surface is the outer sphere (|y| > 0.6 leaves the small sphere).
  CameraFrame frame = make_camera_frame(s.camera, 101, 101);
  for (int y = 0; y < 101; ++y) {
    glm::vec3 d = camera_ray_direction(frame, 50.5f, y + 0.5f);
    Ray r{s.camera.eye, d, 0, INFINITY};
    float big_front = 0, big_back = 0, small_front = 0, small_back = 0;
    if (!sphere_interval(r, {{0, 0, 0}, 1.0f}, big_front, big_back)) continue;
    // Entering the big sphere inside the small one: the surface seen is the small one's exit.
    bool bitten = sphere_interval(r, {{0, 0, 1}, 0.6f}, small_front, small_back) &&
                  small_front < big_front && small_back > big_front;
    size_t i = fb.index(50, y);
    ASSERT_EQ(fb.object_id[i], 0u) << "row " << y;
    EXPECT_NEAR(fb.depth[i], bitten ? small_back : big_front, 2e-3f) << "row " << y;
  }
}

// The intersection of two spheres is a lens: seen from afar, a pixel is covered exactly when
// its ray passes through both spheres with overlapping intervals, which for this symmetric
// pair means within both silhouettes.
TEST(Tracer, CsgIntersectionHasTheLensSilhouette) {
  Scene s = empty_scene(160, 120, {0, 0, 8}, {0, 0, 0}, 25);
  Object o;
  o.type = ObjectType::Csg;
  o.csg = csg_op(CsgOp::Intersection, csg_leaf({-0.5f, 0, 0}, 1.0f), csg_leaf({0.5f, 0, 0}, 1.0f));
  s.objects.push_back(o);
  RenderOutput out = trace(s, RenderMode::Visibility);
  const FrameBuffers& fb = out.buffers;
  CameraFrame frame = make_camera_frame(s.camera, s.image.width, s.image.height);
  const int w = s.image.width, h = s.image.height;
  std::vector<int> expected(size_t(w * h), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 d = glm::normalize(camera_ray_direction(frame, x + 0.5f, y + 0.5f));
      auto dist = [&](glm::vec3 c) { return glm::length(glm::cross(c - s.camera.eye, d)); };
      expected[y * w + x] = dist({-0.5f, 0, 0}) < 1.0f && dist({0.5f, 0, 0}) < 1.0f;
    }
  std::vector<bool> boundary = class_boundary(expected, w, h);
  size_t covered = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    if (boundary[i]) continue;
    covered += expected[i];
    EXPECT_EQ(fb.object_id[i] == 0u, expected[i] == 1) << "pixel " << i % w << "," << i / w;
  }
  EXPECT_GT(covered, 1000u);
}

// A convex object cannot shadow itself: in full mode its lit side must equal local shading
// exactly. A shadow ray that starts too close to the surface re-hits it (shadow acne) and
// darkens a lit pixel; one offset too far leaks light. Checked on an analytic sphere, a
// tessellated sphere and a plane, with the light low so many rays graze.
TEST(Tracer, NoShadowAcneOnConvexSurfaces) {
  for (SphereMode mode : {SphereMode::Analytic, SphereMode::Mesh}) {
    Scene s = empty_scene(160, 120, {0, 1, 4}, {0, 0.5f, 0}, 45);
    uint32_t white = add_material(s, glm::vec3(0.8f));
    s.materials[white].specular = glm::vec3(0.3f);
    add_plane(s, {0, 0, 0}, {0, 1, 0}, 0.9f, white);
    add_sphere(s, {0, 1.4f, 0}, 0.5f, white);  // floats above the plane's edge: no shadow on it
    const glm::vec3 light(3.0f, 0.8f, 2.0f);
    s.lights.push_back({LightType::Point, light, {}, {}, {}, glm::vec3(10.0f), 1});
    CameraFrame frame = make_camera_frame(s.camera, s.image.width, s.image.height);
    RayTracer tracer;
    RenderOptions o;
    o.spheres = mode;
    o.sphere_segments = 64;
    o.mode = RenderMode::Full;
    RenderOutput full = std::move(tracer.render(s, o)).value();
    o.mode = RenderMode::Local;
    RenderOutput local = std::move(tracer.render(s, o)).value();
    size_t lit = 0, differ = 0;
    for (size_t i = 0; i < full.buffers.pixel_count(); ++i) {
      if (full.buffers.object_id[i] == kNoId) continue;
      // The plane's far part is shadowed by the sphere for real: compare only pixels that
      // the sphere cannot shadow, i.e. the sphere itself and the plane in front of it.
      if (full.buffers.object_id[i] == 0 && full.buffers.depth[i] > 4.0f) continue;
      // Only points facing the light: behind the terminator the surface shadows itself for
      // real (Blinn-Phong's specular term is not zero there, the shadow ray correctly is).
      int x = int(i % size_t(s.image.width)), y = int(i / size_t(s.image.width));
      glm::vec3 p =
          s.camera.eye + full.buffers.depth[i] * camera_ray_direction(frame, x + 0.5f, y + 0.5f);
      // On the tessellated sphere the flat facets differ from the interpolated normal by up to
      // half a facet (pi/64, sin = 0.05): within that band of the terminator a facet can face
      // away from the light while its smooth normal faces it, and the mesh really does block
      // the shadow ray (the "shadow terminator" of smooth-shaded meshes, not acne).
      float band = mode == SphereMode::Mesh ? 0.06f : 0.0f;
      if (glm::dot(full.buffers.normal[i], glm::normalize(light - p)) <= band) continue;
      ++lit;
      differ += full.buffers.colour[i] != local.buffers.colour[i];
    }
    EXPECT_GT(lit, 1500u);
    EXPECT_EQ(differ, 0u) << (mode == SphereMode::Mesh ? "tessellated" : "analytic") << " sphere";
  }
}

// The tracer's batched shading of primary hits against the scalar code it replaced, computed
// here one pixel at a time from the tracer's own queries: the ray through the pixel centre
// (camera_ray_direction), its closest hit, the surface there, V = -normalize(d), face_viewer and
// shade_local. Every kernel and both sphere modes give those bits, colour and normal, in local
// mode; visibility mode writes the same depth and ids, the background colour and no normal.
TEST(Tracer, BatchedShadingGivesTheScalarShadingBitForBit) {
  for (const char* name : {"cornell", "spheres", "tessphere:500"}) {
    Expected<Scene> loaded = make_builtin_scene(name);
    ASSERT_TRUE(loaded.ok());
    Scene s = *loaded;
    s.image.width = 83;  // blocks and tiles cut at odd places
    s.image.height = 61;
    const CameraFrame frame = make_camera_frame(s.camera, s.image.width, s.image.height);
    const std::vector<LightSample> lights = light_samples(s.lights);
    for (SphereMode spheres : {SphereMode::Analytic, SphereMode::Mesh}) {
      TraceGeometry geometry(s, spheres, 24, AccelKind::Bvh);
      ASSERT_TRUE(geometry.error().empty());
      for (Isa isa : kAllIsas) {
        if (!cpu_supports(isa)) continue;
        RenderOptions o;
        o.mode = RenderMode::Local;
        o.isa = isa;
        o.spheres = spheres;
        RayTracer tracer;
        Expected<RenderOutput> local = tracer.render(s, o, geometry);
        o.mode = RenderMode::Visibility;
        Expected<RenderOutput> visibility = tracer.render(s, o, geometry);
        ASSERT_TRUE(local.ok() && visibility.ok());
        const FrameBuffers& fb = local->buffers;
        const FrameBuffers& vis = visibility->buffers;
        EXPECT_EQ(local->info.at("shade_kernel"), to_string(isa));
        int covered = 0, wrong = 0;
        for (int y = 0; y < s.image.height; ++y)
          for (int x = 0; x < s.image.width; ++x) {
            const size_t i = fb.index(x, y);
            Ray ray;
            ray.origin = frame.eye;
            ray.dir = camera_ray_direction(frame, float(x) + 0.5f, float(y) + 0.5f);
            ray.tmin = s.camera.near;
            ray.tmax = s.camera.far;
            HitRecord hit;
            glm::vec3 colour = s.image.background, normal(0.0f);
            uint32_t object = kNoId;
            if (geometry.closest(ray, hit)) {
              const SurfaceHit sh = geometry.surface(ray, hit);
              const glm::vec3 V = -glm::normalize(ray.dir);
              normal = face_viewer(sh.shading_normal, sh.geometric_normal, V);
              colour =
                  shade_local(s.materials[sh.material], sh.position, normal, V, s.ambient, lights);
              object = sh.object;
              ++covered;
            }
            const bool same = std::memcmp(&fb.colour[i], &colour, sizeof colour) == 0 &&
                              std::memcmp(&fb.normal[i], &normal, sizeof normal) == 0 &&
                              fb.object_id[i] == object && vis.object_id[i] == object &&
                              vis.primitive_id[i] == fb.primitive_id[i] &&
                              std::memcmp(&vis.depth[i], &fb.depth[i], sizeof(float)) == 0 &&
                              vis.colour[i] == s.image.background &&
                              vis.normal[i] == glm::vec3(0.0f);
            if (!same && ++wrong <= 3)
              ADD_FAILURE() << name << " " << to_string(isa) << " pixel (" << x << ", " << y
                            << ") differs from the scalar shading";
          }
        EXPECT_GT(covered, s.image.width * s.image.height / 10) << name;
      }
    }
  }
}

// Primary rays from the per-frame column and row tables are camera_ray_direction's rays to the
// bit, as packets of any shape and one at a time, for sizes whose ndc steps are not exact.
TEST(Tracer, PrimaryRaysAreTheCameraRaysBitForBit) {
  Camera camera;
  camera.eye = {0.3f, -1.7f, 4.1f};
  camera.target = {-0.2f, 0.4f, -0.9f};
  camera.up = {0.1f, 1.0f, 0.05f};
  camera.fov_y_deg = 53.0f;
  for (auto [w, h] : {std::pair{1024, 768}, {97, 61}, {3, 700}}) {
    const CameraFrame frame = make_camera_frame(camera, w, h);
    const PrimaryRays rays(frame, 0.25f, 80.0f);
    int wrong = 0;
    for (int y0 = 0; y0 < h; y0 += 8)
      for (int x0 = 0; x0 < w; x0 += 8) {
        const int pw = std::min(8, w - x0), ph = std::min(8, h - y0);
        const RayPacket packet = rays.packet(x0, y0, pw, ph);
        ASSERT_EQ(packet.count, pw * ph);
        for (int k = 0; k < packet.count; ++k) {
          const int x = x0 + k % pw, y = y0 + k / pw;
          const glm::vec3 want = camera_ray_direction(frame, float(x) + 0.5f, float(y) + 0.5f);
          const Ray one = rays.ray(x, y), of_packet = PrimaryRays::ray_of(packet, k);
          const bool same = std::memcmp(&one.dir, &want, sizeof want) == 0 &&
                            std::memcmp(&of_packet.dir, &want, sizeof want) == 0 &&
                            one.origin == frame.eye && of_packet.origin == frame.eye &&
                            of_packet.tmin == 0.25f && of_packet.tmax == 80.0f;
          if (!same && ++wrong <= 3)
            ADD_FAILURE() << w << "x" << h << " pixel (" << x << ", " << y << ")";
        }
      }
  }
}
