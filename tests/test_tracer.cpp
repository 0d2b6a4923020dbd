// The tracer's images checked against geometry worked out by hand: shadows, mirrors, CSG,
// and the same bytes whatever the thread count.
#include <gtest/gtest.h>

#include <cstring>

#include "rvr/raytrace/intersect.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/shared/camera.h"
#include "rvr/shared/scene_loader.h"
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
  ASSERT_EQ(one.buffers.color.size(), two.buffers.color.size());
  EXPECT_EQ(std::memcmp(one.buffers.color.data(), two.buffers.color.data(),
                        one.buffers.color.size() * sizeof(glm::vec3)),
            0);
  EXPECT_EQ(one.buffers.object_id, two.buffers.object_id);
  EXPECT_EQ(one.buffers.cost, two.buffers.cost);
  EXPECT_EQ(one.stats.at("rays.shadow"), two.stats.at("rays.shadow"));
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
    bool dark = fb.color[i] == glm::vec3(0.0f);
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
      EXPECT_EQ(fb.color[i], glm::vec3(1, 0, 0)) << "pixel " << i % w << "," << i / w;
    } else {
      EXPECT_NE(fb.color[i], glm::vec3(1, 0, 0)) << "pixel " << i % w << "," << i / w;
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
  EXPECT_GT(fb.color[centre].x, 0.1f);  // lit: the inner wall faces the light at the eye
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
      differ += full.buffers.color[i] != local.buffers.color[i];
    }
    EXPECT_GT(lit, 1500u);
    EXPECT_EQ(differ, 0u) << (mode == SphereMode::Mesh ? "tessellated" : "analytic") << " sphere";
  }
}
