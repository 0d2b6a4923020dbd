// GlRasterizer on hand-built scenes: ids, exact depth, shading equal to the C++ shade_local,
// image orientation, tessellated shapes, csg, stats and the driver checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <glm/glm.hpp>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/camera.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shading.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/square.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/tessellate.h"
#include "rvr/raster/gl_rasterizer.h"
#include "rvr/scene_io/scene_loader.h"
#include "visibility_frame.h"

namespace rvr {
namespace {

constexpr int kW = 64, kH = 48;
const float kInf = std::numeric_limits<float>::infinity();

// Camera at z = 5 looking at the origin; one point light near the eye; a shiny material.
Scene base_scene() {
  Scene s;
  s.source = "test";
  s.image.width = kW;
  s.image.height = kH;
  s.image.background = {0.1f, 0.2f, 0.3f};
  s.camera.eye = {0, 0, 5};
  s.camera.target = {0, 0, 0};
  s.camera.up = {0, 1, 0};
  s.camera.fov_y_deg = 60;
  s.camera.near = 0.1f;
  s.camera.far = 100;
  s.camera.focus_distance = 5;
  s.ambient = {0.05f, 0.05f, 0.05f};
  s.materials.push_back(default_material());
  Material m;
  m.name = "shiny";
  m.diffuse = {0.7f, 0.4f, 0.2f};
  m.specular = {0.5f, 0.5f, 0.5f};
  m.emission = {0.01f, 0.0f, 0.02f};
  m.shininess = 20;
  s.materials.push_back(m);
  Light l;
  l.type = LightType::Point;
  l.position = {1, 2, 4};
  l.intensity = {10, 9, 8};
  s.lights.push_back(l);
  return s;
}

Object triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, uint32_t material = 1,
                const std::string& name = "tri") {
  Object o;
  o.name = name;
  o.type = ObjectType::Triangles;
  o.material = material;
  o.mesh.positions = {a, b, c};
  o.mesh.triangles = {{0, 1, 2}};
  return o;
}

// Axis-aligned square facing +z at depth z, as two triangles (prim 0 and 1).
Object quad(float half, float z, const std::string& name = "quad") {
  Object o;
  o.name = name;
  o.type = ObjectType::Triangles;
  o.material = 1;
  o.mesh.positions = {{-half, -half, z}, {half, -half, z}, {half, half, z}, {-half, half, z}};
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return o;
}

RenderOutput render_ok(const Scene& s, RenderMode mode = RenderMode::Local,
                       GlRasterizer* rasterizer = nullptr,
                       Supersampling supersampling = Supersampling::Accumulation) {
  GlRasterizer local;
  GlRasterizer& r = rasterizer ? *rasterizer : local;
  RenderOptions options;
  options.mode = mode;
  options.supersampling = supersampling;
  auto out = r.render(s, options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  if (!out.ok()) return RenderOutput{};
  return std::move(out.value());
}

// The pixel containing the projection of world point p (y = 0 at the top).
glm::ivec2 pixel_of(const Scene& s, const glm::vec3& p) {
  glm::vec4 clip = projection_matrix(s.camera, s.image.width, s.image.height) *
                   view_matrix(s.camera) * glm::vec4(p, 1.0f);
  glm::vec3 ndc = glm::vec3(clip) / clip.w;
  float px = (ndc.x * 0.5f + 0.5f) * float(s.image.width);
  float py = (0.5f - ndc.y * 0.5f) * float(s.image.height);
  return {int(std::floor(px)), int(std::floor(py))};
}

// Where the ray through pixel (x, y)'s centre meets the plane of triangle (a, b, c); t is the
// view depth because the ray direction has unit component along the view axis.
struct Hit {
  float t;
  glm::vec3 P, geometric_normal, V;
};
Hit hit_plane(const Scene& s, glm::ivec2 pixel, const glm::vec3& a, const glm::vec3& b,
              const glm::vec3& c) {
  CameraFrame f = make_camera_frame(s.camera, s.image.width, s.image.height);
  glm::vec3 d = camera_ray_direction(f, float(pixel.x) + 0.5f, float(pixel.y) + 0.5f);
  glm::vec3 g = glm::cross(b - a, c - a);
  float t = glm::dot(a - f.eye, g) / glm::dot(d, g);
  glm::vec3 P = f.eye + t * d;
  return {t, P, g, glm::normalize(f.eye - P)};
}

void expect_vec_near(const glm::vec3& got, const glm::vec3& want, float tol,
                     const std::string& what) {
  EXPECT_NEAR(got.x, want.x, tol) << what;
  EXPECT_NEAR(got.y, want.y, tol) << what;
  EXPECT_NEAR(got.z, want.z, tol) << what;
}

TEST(GlRaster, SingleTriangleCentroidMatchesAnalyticDepthAndShading) {
  Scene s = base_scene();
  glm::vec3 a(-1.5f, -1.0f, -0.5f), b(1.5f, -1.2f, 0.3f), c(0.2f, 1.4f, -0.2f);
  s.objects.push_back(triangle(a, b, c));
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  ASSERT_EQ(fb.width, kW);
  ASSERT_EQ(fb.height, kH);
  ASSERT_EQ(fb.colour.size(), size_t(kW * kH));

  glm::ivec2 px = pixel_of(s, (a + b + c) / 3.0f);
  size_t i = fb.index(px.x, px.y);
  EXPECT_EQ(fb.object_id[i], 0u);
  EXPECT_EQ(fb.primitive_id[i], 0u);

  Hit h = hit_plane(s, px, a, b, c);
  EXPECT_NEAR(fb.depth[i], h.t, 1e-4f * h.t);
  glm::vec3 N = face_viewer(glm::normalize(h.geometric_normal), h.geometric_normal, h.V);
  expect_vec_near(fb.normal[i], N, 1e-4f, "normal");
  glm::vec3 want = shade_local(s.materials[1], h.P, N, h.V, s.ambient, light_samples(s.lights));
  expect_vec_near(fb.colour[i], want, 1e-3f, "colour");
}

TEST(GlRaster, PixelsOutsideAreBackground) {
  Scene s = base_scene();
  s.objects.push_back(triangle({-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0, 0.5f, 0}));
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  for (glm::ivec2 p : {glm::ivec2(0, 0), glm::ivec2(kW - 1, 0), glm::ivec2(0, kH - 1),
                       glm::ivec2(kW - 1, kH - 1)}) {
    size_t i = fb.index(p.x, p.y);
    EXPECT_EQ(fb.object_id[i], kNoId);
    EXPECT_EQ(fb.primitive_id[i], kNoId);
    EXPECT_EQ(fb.depth[i], kInf);
    EXPECT_EQ(fb.colour[i], s.image.background);
    EXPECT_EQ(fb.normal[i], glm::vec3(0.0f));
    EXPECT_EQ(fb.cost[i], 0.0f);
  }
}

TEST(GlRaster, QuadAtKnownDistanceHasExactDepthAndBothPrimitives) {
  Scene s = base_scene();
  s.objects.push_back(quad(1.0f, -3.0f));  // 8 units in front of the eye
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  size_t covered = 0;
  std::set<uint32_t> prims;
  for (size_t i = 0; i < fb.pixel_count(); ++i) {
    if (fb.object_id[i] == kNoId) continue;
    ++covered;
    prims.insert(fb.primitive_id[i]);
    EXPECT_NEAR(fb.depth[i], 8.0f, 8.0f * 1e-5f);
    expect_vec_near(fb.normal[i], {0, 0, 1}, 1e-6f, "normal");
  }
  // Side 2 at distance 8 with a 60 degree fov covers about (2 / (2*8*tan30) * 48)^2 pixels.
  EXPECT_GT(covered, 80u);
  EXPECT_LT(covered, 140u);
  EXPECT_EQ(prims, (std::set<uint32_t>{0, 1}));
}

TEST(GlRaster, NearerTriangleWinsWhateverTheOrder) {
  for (bool near_first : {false, true}) {
    Scene s = base_scene();
    Object near_tri = triangle({-1, -1, 1}, {1, -1, 1}, {0, 1, 1}, 1, "near");
    Object far_tri = triangle({-1.5f, -1.5f, -1}, {1.5f, -1.5f, -1}, {0, 1.5f, -1}, 1, "far");
    if (near_first) {
      s.objects = {near_tri, far_tri};
    } else {
      s.objects = {far_tri, near_tri};
    }
    uint32_t near_id = near_first ? 0u : 1u;
    RenderOutput out = render_ok(s);
    const FrameBuffers& fb = out.buffers;
    size_t i = fb.index(kW / 2, kH / 2);
    EXPECT_EQ(fb.object_id[i], near_id) << "near_first=" << near_first;
    EXPECT_NEAR(fb.depth[i], 4.0f, 4e-4f);
    EXPECT_EQ(fb.cost[i], 2.0f);  // both triangles generated a fragment here
  }
}

TEST(GlRaster, RowZeroIsTheTop) {
  Scene s = base_scene();
  s.objects.push_back(triangle({-0.5f, 0.5f, 0}, {0.5f, 0.5f, 0}, {0, 1.5f, 0}));
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  size_t covered = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (fb.object_id[fb.index(x, y)] != kNoId) {
        ++covered;
        EXPECT_LT(y, kH / 2) << "covered pixel in the lower half at y=" << y;
      }
  EXPECT_GT(covered, 10u);
  // The apex (y = 1.5) is nearer the top than the base (y = 0.5).
  EXPECT_LT(pixel_of(s, {0, 1.4f, 0}).y, pixel_of(s, {0, 0.6f, 0}).y);
  EXPECT_EQ(fb.object_id[fb.index(pixel_of(s, {0, 1.2f, 0}).x, pixel_of(s, {0, 1.2f, 0}).y)], 0u);
}

TEST(GlRaster, ObjectIdsFollowObjectOrder) {
  Scene s = base_scene();
  const float xs[3] = {-2.0f, 0.0f, 2.0f};
  for (int k = 0; k < 3; ++k) {
    float x = xs[k];
    std::string name = "t";  // (not "t" + to_string: g++ 12 warns -Wrestrict falsely)
    name += std::to_string(k);
    s.objects.push_back(
        triangle({x - 0.6f, -0.5f, 0}, {x + 0.6f, -0.5f, 0}, {x, 0.7f, 0}, 1, name));
  }
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  for (int k = 0; k < 3; ++k) {
    glm::ivec2 p = pixel_of(s, {xs[k], 0.0f, 0.0f});
    EXPECT_EQ(fb.object_id[fb.index(p.x, p.y)], uint32_t(k));
    EXPECT_EQ(fb.primitive_id[fb.index(p.x, p.y)], 0u);
  }
  EXPECT_EQ(out.stats.at("triangles.submitted"), 3.0);
}

TEST(GlRaster, PrimitiveIdRestartsPerObject) {
  Scene s = base_scene();
  s.objects.push_back(quad(0.8f, 0.0f, "left"));
  for (glm::vec3& p : s.objects[0].mesh.positions) p.x -= 1.0f;
  s.objects.push_back(quad(0.8f, 0.0f, "right"));
  for (glm::vec3& p : s.objects[1].mesh.positions) p.x += 1.0f;
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  std::set<std::pair<uint32_t, uint32_t>> seen;
  for (size_t i = 0; i < fb.pixel_count(); ++i)
    if (fb.object_id[i] != kNoId) seen.insert({fb.object_id[i], fb.primitive_id[i]});
  EXPECT_EQ(seen, (std::set<std::pair<uint32_t, uint32_t>>{{0, 0}, {0, 1}, {1, 0}, {1, 1}}));
}

TEST(GlRaster, SphereIsTessellatedWithPrimitiveIdZero) {
  Scene s = base_scene();
  Object o;
  o.name = "ball";
  o.type = ObjectType::Sphere;
  o.material = 1;
  o.sphere = {{0, 0, 0}, 1.0f};
  s.objects.push_back(o);
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  size_t covered = 0;
  for (size_t i = 0; i < fb.pixel_count(); ++i) {
    if (fb.object_id[i] == kNoId) continue;
    ++covered;
    EXPECT_EQ(fb.object_id[i], 0u);
    EXPECT_EQ(fb.primitive_id[i], 0u);
    EXPECT_NEAR(glm::length(fb.normal[i]), 1.0f, 1e-4f);
    EXPECT_GT(fb.normal[i].z, 0.0f);  // facing the viewer
  }
  EXPECT_GT(covered, 100u);
  // The z-buffer draws the tessellation, so compare with the ray through the centre pixel
  // hitting that same mesh (Moller-Trumbore over every triangle, nearest hit).
  size_t c = fb.index(kW / 2, kH / 2);
  CameraFrame f = make_camera_frame(s.camera, kW, kH);
  glm::vec3 d = camera_ray_direction(f, kW / 2 + 0.5f, kH / 2 + 0.5f);
  TriangleMesh mesh = tessellate_sphere(o.sphere, RenderOptions{}.sphere_segments);
  float best = kInf;
  glm::vec3 best_normal(0.0f);
  for (const glm::uvec3& tri : mesh.triangles) {
    glm::vec3 p0 = mesh.positions[tri.x], e1 = mesh.positions[tri.y] - p0,
              e2 = mesh.positions[tri.z] - p0;
    glm::vec3 pv = glm::cross(d, e2);
    float det = glm::dot(e1, pv);
    if (std::abs(det) < 1e-12f) continue;
    glm::vec3 tv = f.eye - p0;
    float u = glm::dot(tv, pv) / det;
    glm::vec3 qv = glm::cross(tv, e1);
    float v = glm::dot(d, qv) / det;
    float t = glm::dot(e2, qv) / det;
    if (u < 0 || v < 0 || u + v > 1 || t <= 0 || t >= best) continue;
    best = t;
    best_normal = glm::normalize((1 - u - v) * mesh.normals[tri.x] + u * mesh.normals[tri.y] +
                                 v * mesh.normals[tri.z]);
  }
  ASSERT_LT(best, kInf);
  EXPECT_NEAR(fb.depth[c], best, 1e-4f * best);
  expect_vec_near(fb.normal[c], best_normal, 1e-4f, "centre normal");
  RenderOptions defaults;
  EXPECT_EQ(out.stats.at("triangles.submitted"),
            double(tessellate_sphere(o.sphere, defaults.sphere_segments).triangle_count()));
}

TEST(GlRaster, PlaneIsTessellatedAndFacesTheViewer) {
  for (float nz : {1.0f, -1.0f}) {
    Scene s = base_scene();
    Object o;
    o.name = "floor";
    o.type = ObjectType::Plane;
    o.material = 1;
    o.plane = {{0, 0, -1}, {0, 0, nz}, 1.0f};
    s.objects.push_back(o);
    RenderOutput out = render_ok(s);
    const FrameBuffers& fb = out.buffers;
    glm::ivec2 p = pixel_of(s, {0.3f, 0.2f, -1.0f});
    size_t i = fb.index(p.x, p.y);
    EXPECT_EQ(fb.object_id[i], 0u);
    EXPECT_EQ(fb.primitive_id[i], 0u);
    TriangleMesh m = tessellate_plane(o.plane);
    Hit h = hit_plane(s, p, m.positions[0], m.positions[1], m.positions[2]);
    EXPECT_NEAR(fb.depth[i], h.t, 1e-4f * h.t);
    expect_vec_near(fb.normal[i], {0, 0, 1}, 1e-5f, "normal flipped to the viewer");
    glm::vec3 N = face_viewer(o.plane.normal, o.plane.normal, h.V);
    glm::vec3 want = shade_local(s.materials[1], h.P, N, h.V, s.ambient, light_samples(s.lights));
    expect_vec_near(fb.colour[i], want, 1e-3f, "colour");
  }
}

TEST(GlRaster, SmoothNormalsFlipByTheGeometricNormal) {
  Scene s = base_scene();
  // Wound clockwise seen from the camera (face normal points away), vertex normals towards
  // the camera: face_viewer must flip the interpolated normal because of the face normal.
  Object o = triangle({-1, -1, 0}, {0, 1, 0}, {1, -1, 0});
  glm::vec3 n = glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f));
  o.mesh.normals = {n, n, n};
  s.objects.push_back(o);
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  glm::ivec2 p = pixel_of(s, {0, -0.3f, 0});
  size_t i = fb.index(p.x, p.y);
  ASSERT_EQ(fb.object_id[i], 0u);
  expect_vec_near(fb.normal[i], -n, 1e-5f, "flipped smooth normal");
  const glm::vec3 &a = o.mesh.positions[0], &b = o.mesh.positions[1], &c = o.mesh.positions[2];
  Hit h = hit_plane(s, p, a, b, c);
  glm::vec3 N = face_viewer(n, h.geometric_normal, h.V);
  glm::vec3 want = shade_local(s.materials[1], h.P, N, h.V, s.ambient, light_samples(s.lights));
  expect_vec_near(fb.colour[i], want, 1e-3f, "colour");
}

TEST(GlRaster, ThousandsOfAreaLightSamplesMatchCpuShading) {
  Scene s = base_scene();
  Light area;
  area.type = LightType::Area;
  area.corner = {-2, 3, 1};
  area.edge_u = {4, 0, 0};
  area.edge_v = {0, 0, 3};
  area.intensity = {30, 30, 30};
  area.samples = 50;  // 2500 samples
  s.lights.push_back(area);
  glm::vec3 a(-2, -1.5f, -1), b(2, -1.5f, -1), c(0, 1.5f, 0);
  s.objects.push_back(triangle(a, b, c));
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  glm::ivec2 p = pixel_of(s, (a + b + c) / 3.0f);
  size_t i = fb.index(p.x, p.y);
  ASSERT_EQ(fb.object_id[i], 0u);
  Hit h = hit_plane(s, p, a, b, c);
  glm::vec3 N = face_viewer(glm::normalize(h.geometric_normal), h.geometric_normal, h.V);
  auto samples = light_samples(s.lights);
  ASSERT_EQ(samples.size(), 2501u);
  glm::vec3 want = shade_local(s.materials[1], h.P, N, h.V, s.ambient, samples);
  expect_vec_near(fb.colour[i], want, 1e-3f * std::max(1.0f, want.x), "colour");
}

// A CSG solid of one leaf, a unit sphere at the origin, is drawn leaf by leaf (two depth passes
// for its one leaf, test_csg_zbuffer holds the combination to closed forms): seen at the
// centre and shaded there, ids still object indices, and its stats count what the frame shows.
TEST(GlRaster, CsgSolidIsDrawnLeafByLeafInTheCameraAndTheShadowCubes) {
  Scene s = base_scene();
  Object csg;
  csg.name = "carved";
  csg.type = ObjectType::Csg;
  csg.material = 1;
  auto leaf = std::make_shared<CsgNode>();
  leaf->sphere = {{0, 0, 0}, 1.0f};
  csg.csg = leaf;
  s.objects.push_back(csg);
  s.objects.push_back(triangle({1, 1, 0}, {2, 1, 0}, {1.5f, 2, 0}));
  RenderOutput out = render_ok(s);
  const FrameBuffers& fb = out.buffers;
  const size_t centre = fb.index(kW / 2, kH / 2);
  EXPECT_EQ(fb.object_id[centre], 0u);
  EXPECT_EQ(fb.primitive_id[centre], 0u);  // CSG objects name no primitive (docs/design.md)
  // The sphere's front at the centre pixel: view depth 4 within the tessellation's sag.
  EXPECT_NEAR(fb.depth[centre], 4.0f, 0.01f);
  EXPECT_GT(fb.normal[centre].z, 0.99f);
  glm::ivec2 p = pixel_of(s, {1.5f, 1.3f, 0});
  EXPECT_EQ(fb.object_id[fb.index(p.x, p.y)], 1u);  // ids stay object indices
  EXPECT_TRUE(out.warnings.empty()) << out.warnings[0];
  const size_t shown = size_t(std::count(fb.object_id.begin(), fb.object_id.end(), 0u));
  EXPECT_GT(shown, 100u);
  EXPECT_EQ(out.stats.at("csg.objects"), 1.0);
  EXPECT_EQ(out.stats.at("csg.leaf_passes"), 2.0);
  EXPECT_EQ(out.stats.at("csg.pixels"), double(shown));

  // Full mode: the solid is drawn into the faces of the light's shadow cube it shows in as
  // well (test_shadow_agreement holds those shadows to the tracer's rays), without a warning.
  RenderOutput full = render_ok(s, RenderMode::Full);
  EXPECT_EQ(full.buffers.object_id, fb.object_id);
  EXPECT_TRUE(full.warnings.empty()) << full.warnings[0];
  EXPECT_GT(full.stats.at("csg.leaf_passes"), 2.0);
}

// A scene with no material list (hand-made, as library users build them) is drawn in the
// built-in grey, which the draws must still find when the scene pass reads their materials:
// the same bytes as the grey given as the scene's one material.
TEST(GlRaster, SceneWithoutMaterialsIsDrawnInTheBuiltInGrey) {
  Scene listed = base_scene();
  listed.materials = {default_material()};
  listed.objects.push_back(quad(1.0f, 0.0f));
  listed.objects.back().material = 0;
  listed.objects.push_back(triangle({1, 1, 0.5f}, {2, 1, 0.5f}, {1.5f, 2, 0.5f}, 0));
  Scene unlisted = listed;
  unlisted.materials.clear();
  const RenderOutput expected = render_ok(listed);
  const RenderOutput out = render_ok(unlisted);
  const FrameBuffers &a = out.buffers, &b = expected.buffers;
  ASSERT_EQ(a.pixel_count(), b.pixel_count());
  const size_t centre = a.index(kW / 2, kH / 2);
  EXPECT_EQ(a.object_id[centre], 0u);
  EXPECT_NE(a.colour[centre], listed.image.background);
  size_t differing = 0;
  for (size_t i = 0; i < a.pixel_count(); ++i) differing += a.colour[i] != b.colour[i] ? 1 : 0;
  EXPECT_EQ(differing, 0u);
}

TEST(GlRaster, VisibilityModeKeepsBackgroundColour) {
  Scene s = base_scene();
  s.objects.push_back(quad(1.0f, 0.0f));
  RenderOutput out = render_ok(s, RenderMode::Visibility);
  const FrameBuffers& fb = out.buffers;
  size_t i = fb.index(kW / 2, kH / 2);
  EXPECT_EQ(fb.object_id[i], 0u);
  EXPECT_NEAR(fb.depth[i], 5.0f, 5e-5f);
  EXPECT_EQ(fb.colour[i], s.image.background);
  EXPECT_TRUE(out.warnings.empty());
}

// Visibility mode reads back ids and depth only: depth, ids and cost as local mode's
// (visibility_frame.h), colour the background, normal 0. Without the cost AOV no cost pass
// runs (no time.cost, no fragments.generated) and the cost is 0.
TEST(GlRaster, VisibilityModeWritesIdsDepthAndCostOnly) {
  for (const char* name : {"cornell", "spheres", "tessphere:1000"}) {
    Expected<Scene> loaded = make_builtin_scene(name);
    ASSERT_TRUE(loaded.ok()) << name;
    Scene scene = *loaded;
    scene.image.width = 203;
    scene.image.height = 151;
    GlRasterizer r;
    RenderOptions options;
    options.mode = RenderMode::Local;
    Expected<RenderOutput> local = r.render(scene, options);
    ASSERT_TRUE(local.ok()) << local.error().message;
    options.mode = RenderMode::Visibility;
    Expected<RenderOutput> visibility = r.render(scene, options);
    ASSERT_TRUE(visibility.ok()) << visibility.error().message;
    options.cost_aov = false;
    Expected<RenderOutput> no_cost = r.render(scene, options);
    ASSERT_TRUE(no_cost.ok()) << no_cost.error().message;
    test::expect_visibility_frame(scene, local->buffers, visibility->buffers, no_cost->buffers,
                                  name);
    EXPECT_EQ(visibility->stats.count("time.cost"), 1u) << name;
    EXPECT_EQ(no_cost->stats.count("time.cost"), 0u) << name;
    EXPECT_EQ(no_cost->stats.count("fragments.generated"), 0u) << name;
    EXPECT_EQ(no_cost->stats.at("fragments.passed"), visibility->stats.at("fragments.passed"))
        << name;
  }
}

// Without the cost AOV, local and full mode change only the cost, to 0.
TEST(GlRaster, NoCostAovLeavesEveryOtherBufferAsItWas) {
  Scene s = base_scene();
  s.objects.push_back(quad(1.0f, 0.0f));
  s.objects.push_back(triangle({-2, -1, -1}, {1, -1, 0.5f}, {0, 2, -0.5f}));
  for (RenderMode mode : {RenderMode::Local, RenderMode::Full}) {
    GlRasterizer r;
    RenderOptions options;
    options.mode = mode;
    Expected<RenderOutput> with = r.render(s, options);
    ASSERT_TRUE(with.ok()) << with.error().message;
    options.cost_aov = false;
    Expected<RenderOutput> without = r.render(s, options);
    ASSERT_TRUE(without.ok()) << without.error().message;
    test::expect_only_the_cost_left_out(with->buffers, without->buffers, to_string(mode));
    const PixelVector<float>& cost = with->buffers.cost;  // overdraw counted: some pixel above 1
    EXPECT_TRUE(std::any_of(cost.begin(), cost.end(), [](float c) { return c > 1.0f; }));
  }
}

TEST(GlRaster, FullModeWithoutMirrorGlassOrApertureDoesNotWarn) {
  Scene s = base_scene();
  s.objects.push_back(quad(1.0f, 0.0f));
  RenderOutput full = render_ok(s, RenderMode::Full);
  EXPECT_TRUE(full.warnings.empty()) << full.warnings[0];
  // One point light, nothing between it and the quad: shadows change nothing.
  RenderOutput local = render_ok(s, RenderMode::Local);
  for (size_t i = 0; i < full.buffers.pixel_count(); ++i)
    expect_vec_near(full.buffers.colour[i], local.buffers.colour[i], 1e-6f, "lit quad");
  EXPECT_EQ(full.stats.at("shadow_map.maps"), 1.0);
  EXPECT_EQ(full.stats.at("shadow_map.texels"), 6.0 * 1024.0 * 1024.0);
  EXPECT_TRUE(full.stats.count("time.shadow_maps"));
  EXPECT_FALSE(local.stats.count("shadow_map.maps"));
}

TEST(GlRaster, StatsAndCostAreConsistent) {
  Scene s = base_scene();
  s.objects.push_back(quad(1.0f, 0.0f, "front"));
  s.objects.push_back(quad(2.0f, -1.0f, "back"));
  RenderOutput out = render_ok(s);
  for (const char* key : {"time.setup", "time.upload", "time.render", "time.cost", "time.readback",
                          "triangles.submitted", "fragments.generated", "fragments.passed",
                          "pixels.covered", "overdraw"})
    EXPECT_TRUE(out.stats.count(key)) << key;
  EXPECT_EQ(out.stats.at("triangles.submitted"), 4.0);
  const FrameBuffers& fb = out.buffers;
  double sum = 0.0, covered = 0.0;
  for (size_t i = 0; i < fb.pixel_count(); ++i) {
    sum += fb.cost[i];
    if (fb.object_id[i] != kNoId) {
      covered += 1.0;
      EXPECT_GE(fb.cost[i], 1.0f);
    }
  }
  EXPECT_EQ(out.stats.at("fragments.generated"), sum);
  EXPECT_EQ(out.stats.at("pixels.covered"), covered);
  EXPECT_EQ(fb.cost[fb.index(kW / 2, kH / 2)], 2.0f);
  // Back quad drawn after the front one: its fragments behind it fail the depth test.
  EXPECT_GE(out.stats.at("fragments.passed"), covered);
  EXPECT_LT(out.stats.at("fragments.passed"), sum);
}

TEST(GlRaster, ReusesTheContextAcrossSizes) {
  GlRasterizer r;
  Scene s = base_scene();
  s.objects.push_back(quad(1.0f, 0.0f));
  RenderOutput a = render_ok(s, RenderMode::Local, &r);
  s.image.width = 33;
  s.image.height = 17;
  RenderOutput b = render_ok(s, RenderMode::Local, &r);
  RenderOutput c = render_ok(s, RenderMode::Local, &r);
  EXPECT_EQ(a.buffers.width, kW);
  EXPECT_EQ(b.buffers.width, 33);
  EXPECT_EQ(b.buffers.height, 17);
  EXPECT_EQ(b.buffers.colour.size(), size_t(33 * 17));
  EXPECT_EQ(b.buffers.object_id, c.buffers.object_id);
  EXPECT_EQ(b.buffers.colour, c.buffers.colour);
  EXPECT_EQ(b.buffers.object_id[b.buffers.index(16, 8)], 0u);
}

TEST(GlRaster, BadTriangleIndexIsBadInput) {
  Scene s = base_scene();
  Object o = triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  o.mesh.triangles = {{0, 1, 7}};
  s.objects.push_back(o);
  GlRasterizer r;
  auto out = r.render(s, RenderOptions{});
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.error().kind, ErrorKind::BadInput);
}

TEST(GlRaster, QueryGlInfoReportsLlvmpipe) {
  auto info = query_gl_info();
  ASSERT_TRUE(info.ok()) << info.error().message;
  EXPECT_EQ(info->backend, "osmesa");
  EXPECT_NE(info->renderer.find("llvmpipe"), std::string::npos) << info->renderer;
  EXPECT_FALSE(info->version.empty());
  EXPECT_NE(info->version.find("Core Profile"), std::string::npos) << info->version;
  EXPECT_FALSE(info->vendor.empty());
  EXPECT_FALSE(info->glsl_version.empty());
}

// A sphere over a floor under a point light, no ambient, no emission, no specular: a floor
// pixel is black exactly when the shadow map says the light is hidden.
Scene shadow_scene(int w, int h) {
  Scene s = base_scene();
  s.image.width = w;
  s.image.height = h;
  s.ambient = glm::vec3(0.0f);
  s.camera.eye = {0, 4, 4};
  s.camera.target = {0, 0, 0};
  s.camera.fov_y_deg = 45;
  Material m;
  m.name = "matte";
  m.diffuse = {0.8f, 0.8f, 0.8f};
  m.specular = glm::vec3(0.0f);
  s.materials[1] = m;
  s.lights[0].position = {0.8f, 3.0f, -0.4f};
  s.lights[0].intensity = {9, 9, 9};
  Object floor;
  floor.name = "floor";
  floor.type = ObjectType::Plane;
  floor.material = 1;
  floor.plane = {{0, 0, 0}, {0, 1, 0}, 3.0f};
  s.objects.push_back(floor);
  Object ball;
  ball.name = "ball";
  ball.type = ObjectType::Sphere;
  ball.material = 1;
  ball.sphere = {{0, 1, 0}, 0.6f};
  s.objects.push_back(ball);
  return s;
}

TEST(GlRaster, ShadowMapMatchesTheAnalyticShadowOfASphere) {
  const int w = 160, h = 120;
  Scene s = shadow_scene(w, h);
  GlRasterizer r;
  RenderOptions options;
  options.mode = RenderMode::Full;
  auto out = r.render(s, options);
  ASSERT_TRUE(out.ok()) << out.error().message;
  const FrameBuffers& fb = out->buffers;
  const glm::vec3 L = s.lights[0].position, C = s.objects[1].sphere.center;
  const float radius = s.objects[1].sphere.radius;
  CameraFrame f = make_camera_frame(s.camera, w, h);
  // Analytic classification at each pixel centre: -1 not the floor, 1 shadowed, 0 lit.
  std::vector<int> analytic(size_t(w) * size_t(h), -1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 d = camera_ray_direction(f, float(x) + 0.5f, float(y) + 0.5f);
      if (d.y >= 0.0f) continue;
      glm::vec3 P = f.eye + (-f.eye.y / d.y) * d;
      if (std::abs(P.x) > 3.0f || std::abs(P.z) > 3.0f) continue;
      // Distance from the sphere centre to the segment P -> L.
      glm::vec3 seg = L - P;
      float t = std::clamp(glm::dot(C - P, seg) / glm::dot(seg, seg), 0.0f, 1.0f);
      analytic[fb.index(x, y)] = glm::length(P + t * seg - C) < radius ? 1 : 0;
    }
  // Shadow maps are resolution-limited: at 1024 texels per 90 degrees a texel covers about
  // 2/1024 of the distance to the light (~0.006 here, a sixth of a pixel on the floor), the
  // normal offset and slope bias move the edge by about one texel, and the raster's sphere is
  // a 64-segment tessellation (inscribed, up to 0.1% smaller). All of that is well inside a
  // pixel, but the pixel-centre sample can fall either side of the edge: so pixels within 2
  // pixels of a change of the analytic classification (the edge band) are not compared.
  auto near_edge = [&](int x, int y) {
    int c = analytic[fb.index(x, y)];
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx) {
        int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        int o = analytic[fb.index(nx, ny)];
        if (o != c && o != -1) return true;
      }
    return false;
  };
  size_t shadowed = 0, lit = 0, compared = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      size_t i = fb.index(x, y);
      if (analytic[i] < 0 || fb.object_id[i] != 0u || near_edge(x, y)) continue;
      ++compared;
      bool black = fb.colour[i] == glm::vec3(0.0f);
      EXPECT_EQ(black, analytic[i] == 1) << "pixel " << x << "," << y;
      (black ? shadowed : lit) += 1;
    }
  EXPECT_GT(shadowed, 100u);
  EXPECT_GT(lit, 1000u);
  EXPECT_GT(compared, size_t(w * h) / 3);
  EXPECT_EQ(out->stats.at("shadow_map.maps"), 1.0);

  // PCF softens the edge but keeps the core black and the far floor lit.
  options.shadow_pcf = true;
  options.shadow_map_size = 256;
  auto pcf = r.render(s, options);
  ASSERT_TRUE(pcf.ok()) << pcf.error().message;
  EXPECT_EQ(pcf->stats.at("shadow_map.texels"), 6.0 * 256.0 * 256.0);
  size_t differs = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      size_t i = fb.index(x, y);
      if (analytic[i] < 0 || fb.object_id[i] != 0u || near_edge(x, y)) continue;
      bool black = pcf->buffers.colour[i] == glm::vec3(0.0f);
      differs += black != (analytic[i] == 1) ? 1 : 0;
    }
  EXPECT_LE(differs, compared / 100);
}

TEST(GlRaster, AreaLightSamplesEachGetAShadowMap) {
  Scene s = shadow_scene(80, 60);
  Light area;
  area.type = LightType::Area;
  area.corner = {-0.5f, 3.0f, -0.5f};
  area.edge_u = {1, 0, 0};
  area.edge_v = {0, 0, 1};
  area.intensity = {9, 9, 9};
  area.samples = 3;
  s.lights = {area};
  GlRasterizer r;
  RenderOptions options;
  options.mode = RenderMode::Full;
  options.shadow_map_size = 128;
  auto out = r.render(s, options);
  ASSERT_TRUE(out.ok()) << out.error().message;
  EXPECT_EQ(out->stats.at("shadow_map.maps"), 9.0);
  EXPECT_EQ(out->stats.at("shadow_map.texels"), 9.0 * 6.0 * 128.0 * 128.0);
  // Under the ball's centre every sample is hidden: black; far out every sample sees it.
  const FrameBuffers& fb = out->buffers;
  glm::ivec2 under = pixel_of(s, {0.0f, 0.0f, 0.0f});
  glm::ivec2 far_out = pixel_of(s, {2.0f, 0.0f, 2.0f});
  ASSERT_EQ(fb.object_id[fb.index(under.x, under.y)], 0u);
  EXPECT_EQ(fb.colour[fb.index(under.x, under.y)], glm::vec3(0.0f));
  glm::vec3 lit = fb.colour[fb.index(far_out.x, far_out.y)];
  EXPECT_GT(lit.x, 0.0f);
  // Many samples: maps shrink to the texel budget (with a warning) and still work in batches.
  area.samples = 15;  // 225 samples
  s.lights = {area};
  options.shadow_map_size = 1024;
  auto many = r.render(s, options);
  ASSERT_TRUE(many.ok()) << many.error().message;
  EXPECT_EQ(many->stats.at("shadow_map.maps"), 225.0);
  EXPECT_LT(many->stats.at("shadow_map.size"), 1024.0);
  ASSERT_EQ(many->warnings.size(), 1u);
  EXPECT_NE(many->warnings[0].find("shadow maps of"), std::string::npos);
  EXPECT_EQ(many->buffers.colour[fb.index(under.x, under.y)], glm::vec3(0.0f));
  // The lit pixel sees every sample in both renders: same light, same colour.
  expect_vec_near(many->buffers.colour[fb.index(far_out.x, far_out.y)], lit * 1.0f,
                  1e-2f * std::max(lit.x, 1.0f), "lit floor");
}

TEST(GlRaster, MultisamplingBlendsEdgesAndKeepsPerPixelIds) {
  Scene s = base_scene();
  Material glow;
  glow.name = "glow";
  glow.diffuse = glm::vec3(0.0f);
  glow.specular = glm::vec3(0.0f);
  glow.emission = {1.0f, 0.5f, 0.25f};
  s.materials[1] = glow;
  s.objects.push_back(triangle({-1.7f, -1.1f, 0}, {1.3f, -1.4f, 0}, {0.2f, 1.6f, 0}));
  RenderOutput one = render_ok(s, RenderMode::Local);
  s.image.samples_per_pixel = 4;
  GlRasterizer r;
  RenderOutput four = render_ok(s, RenderMode::Local, &r, Supersampling::Msaa);
  EXPECT_TRUE(four.warnings.empty());
  EXPECT_EQ(four.buffers.object_id, one.buffers.object_id);
  EXPECT_EQ(four.buffers.primitive_id, one.buffers.primitive_id);
  EXPECT_EQ(four.buffers.depth, one.buffers.depth);
  EXPECT_EQ(four.buffers.normal, one.buffers.normal);
  const FrameBuffers& fb = four.buffers;
  const glm::vec3 bg = s.image.background, inside = glow.emission;
  // Same id over the 3x3 neighbourhood: the pixel is all one thing.
  auto uniform_id = [&](int x, int y) {
    uint32_t id = fb.object_id[fb.index(x, y)];
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        int nx = std::clamp(x + dx, 0, kW - 1), ny = std::clamp(y + dy, 0, kH - 1);
        if (fb.object_id[fb.index(nx, ny)] != id) return false;
      }
    return true;
  };
  size_t blended = 0, interior = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      size_t i = fb.index(x, y);
      const glm::vec3 c = fb.colour[i];
      EXPECT_TRUE(one.buffers.colour[i] == bg || one.buffers.colour[i] == inside);
      if (uniform_id(x, y)) {
        EXPECT_EQ(c, fb.object_id[i] == 0u ? inside : bg) << x << "," << y;
        interior += fb.object_id[i] == 0u ? 1 : 0;
      } else if (c != bg && c != inside) {
        ++blended;
        // A mix of the two: every channel between them.
        for (int k = 0; k < 3; ++k) {
          EXPECT_GE(c[k], std::min(bg[k], inside[k]) - 1e-6f);
          EXPECT_LE(c[k], std::max(bg[k], inside[k]) + 1e-6f);
        }
      }
    }
  EXPECT_GT(interior, 100u);
  EXPECT_GT(blended, 20u);  // edge pixels with intermediate colours

  s.image.samples_per_pixel = 1 << 16;  // more than any GL allows
  RenderOutput clamped = render_ok(s, RenderMode::Local, &r, Supersampling::Msaa);
  ASSERT_EQ(clamped.warnings.size(), 1u);
  EXPECT_NE(clamped.warnings[0].find("samples per pixel requested"), std::string::npos);
  EXPECT_EQ(clamped.buffers.object_id, one.buffers.object_id);
  // Visibility mode takes no colour samples: no warning.
  EXPECT_TRUE(render_ok(s, RenderMode::Visibility).warnings.empty());
}

TEST(GlRaster, MultisampledFullModeMatchesSingleSampleInside) {
  Scene s = shadow_scene(80, 60);
  RenderOutput one = render_ok(s, RenderMode::Full);
  s.image.samples_per_pixel = 4;
  RenderOutput four = render_ok(s, RenderMode::Full, nullptr, Supersampling::Msaa);
  EXPECT_EQ(four.buffers.object_id, one.buffers.object_id);
  glm::ivec2 far_out = pixel_of(s, {2.0f, 0.0f, 2.0f});
  size_t i = one.buffers.index(far_out.x, far_out.y);
  // Samples spread over the pixel: the shading differs slightly from the centre's.
  expect_vec_near(four.buffers.colour[i], one.buffers.colour[i], 2e-2f, "lit floor");
  glm::ivec2 under = pixel_of(s, {0.0f, 0.0f, 0.0f});
  EXPECT_EQ(four.buffers.colour[one.buffers.index(under.x, under.y)], glm::vec3(0.0f));
}

TEST(GlRaster, FullModeWarnsOnlyAboutWhatTheSceneUses) {
  Scene s = base_scene();
  Material mirror = s.materials[1];
  mirror.name = "chrome";
  mirror.mirror = 0.8f;
  Material glass = s.materials[1];
  glass.name = "crystal";
  glass.transparency = 0.9f;
  glass.ior = 1.5f;
  Material unused = glass;
  unused.name = "unused glass";
  s.materials.push_back(mirror);  // 2
  s.materials.push_back(glass);   // 3
  s.materials.push_back(unused);  // 4, no object uses it
  s.objects.push_back(triangle({-2, -1, 0}, {-1, -1, 0}, {-1.5f, 0, 0}, 2, "m"));
  s.objects.push_back(triangle({1, -1, 0}, {2, -1, 0}, {1.5f, 0, 0}, 3, "g"));
  s.camera.aperture_radius = 0.1f;
  RenderOutput full = render_ok(s, RenderMode::Full);
  // The mirror is flat: reflected (planar_mirrors.h), nothing to say of it.
  ASSERT_EQ(full.warnings.size(), 2u);
  EXPECT_NE(full.warnings[0].find("refraction on 1 transparent object (g) from cube maps"),
            std::string::npos)
      << full.warnings[0];
  EXPECT_EQ(full.warnings[0].find("unused"), std::string::npos);
  EXPECT_NE(full.warnings[1].find(kDepthOfFieldNeedsSamples), std::string::npos)
      << full.warnings[1];
  EXPECT_EQ(full.stats.at("mirror.views"), 1.0);
  // Local mode has no mirror, glass or lens by definition: nothing to warn about.
  EXPECT_TRUE(render_ok(s, RenderMode::Local).warnings.empty());
  // Only the aperture: one warning.
  s.objects = {quad(1.0f, 0.0f)};
  RenderOutput lens = render_ok(s, RenderMode::Full);
  ASSERT_EQ(lens.warnings.size(), 1u);
  EXPECT_NE(lens.warnings[0].find("depth of field"), std::string::npos);
}

// Mesa picks its driver once per process, so the driver checks run in a fresh process
// (the "threadsafe" death-test style re-executes this binary).
int render_error_exit_code(const char* driver, const char* expected_text) {
  setenv("GALLIUM_DRIVER", driver, 1);
  Scene s = base_scene();
  s.objects.push_back(quad(1.0f, 0.0f));
  GlRasterizer r;
  auto out = r.render(s, RenderOptions{});
  if (out.ok()) return 1;
  if (out.error().kind != ErrorKind::Internal) return 2;
  if (out.error().message.find(expected_text) == std::string::npos) return 3;
  return 0;
}

TEST(GlRasterDeathTest, RefusesSoftpipe) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(std::exit(render_error_exit_code("softpipe", "unset GALLIUM_DRIVER")),
              ::testing::ExitedWithCode(0), "");
}

TEST(GlRasterDeathTest, RefusesZinkBeforeItCrashes) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(std::exit(render_error_exit_code("zink", "zink")), ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace rvr
