// Refraction, depth of field and soft shadows against closed-form optics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/core/camera.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/ray.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/raytrace/ray_tracer.h"
#include "scene_builders.h"

using namespace rvr;
using namespace rvr::test;

namespace {

const float kPi = 3.14159265358979f;

RenderOutput trace(const Scene& s, int max_depth = 5) {
  RayTracer tracer;
  RenderOptions o;
  o.mode = RenderMode::Full;
  o.max_depth = max_depth;
  Expected<RenderOutput> out = tracer.render(s, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return std::move(out).value();
}

}  // namespace

// A tilted glass slab in front of a red|blue edge. A ray through a slab of thickness T leaves
// parallel to itself, displaced sideways by T sin(i - r) / cos r (Snell: sin i = n sin r). The
// edge must appear where that displacement puts it, within a pixel.
TEST(Refraction, GlassSlabDisplacesAnEdgeBySnellsLaw) {
  const int w = 800, h = 80;
  Scene s = empty_scene(w, h, {0, 0, 10}, {0, 0, 0}, 4);
  add_plane(s, {-5, 0, -3}, {0, 0, 1}, 5, emissive(s, {1, 0, 0}));  // x < 0: red
  add_plane(s, {5, 0, -3}, {0, 0, 1}, 5, emissive(s, {0, 0, 1}));   // x > 0: blue
  const float ior = 1.5f, thickness = 1.0f, tilt = kPi / 6;
  add_box(s, {3, 3, thickness / 2}, tilt, glass(s, ior));
  RenderOutput out = trace(s);
  CameraFrame frame = make_camera_frame(s.camera, w, h);
  const glm::vec3 n(std::sin(tilt), 0, std::cos(tilt));  // slab front normal

  const int y = h / 2;
  int predicted_edge = -1, rendered_edge = -1;
  for (int x = 0; x < w; ++x) {
    glm::vec3 d = glm::normalize(camera_ray_direction(frame, x + 0.5f, y + 0.5f));
    float cos_i = -glm::dot(d, n);
    float sin_i = std::sqrt(std::max(0.0f, 1.0f - cos_i * cos_i));
    float r = std::asin(sin_i / ior), i = std::acos(cos_i);
    float shift = thickness * std::sin(i - r) / std::cos(r);
    // Inside, the ray bends towards -n: the exit ray is displaced along -n's part across d.
    glm::vec3 across = -n - glm::dot(-n, d) * d;
    glm::vec3 origin = s.camera.eye + shift * glm::normalize(across);
    float t = (-3.0f - origin.z) / d.z;
    float x_hit = origin.x + t * d.x;
    if (predicted_edge < 0 && x_hit > 0) predicted_edge = x;
    glm::vec3 c = out.buffers.colour[out.buffers.index(x, y)];
    if (rendered_edge < 0 && c.z > c.x) rendered_edge = x;
  }
  ASSERT_GT(predicted_edge, 0);
  // The displacement is real: without the slab the edge would be at the centre column.
  EXPECT_GT(std::abs(predicted_edge - w / 2), 10);
  EXPECT_LE(std::abs(rendered_edge - predicted_edge), 1)
      << "rendered " << rendered_edge << " predicted " << predicted_edge;
  EXPECT_GT(out.stats.at("rays.refraction"), 0.0);
}

// From inside glass (n = 1.5) a ray meeting the surface beyond the critical angle
// asin(1/1.5) = 41.8 degrees cannot leave: it reflects. With one bounce allowed, the rays that
// leave show the red wall beyond; the reflected ones end in black.
TEST(Refraction, TotalInternalReflectionBeyondTheCriticalAngle) {
  const int w = 160, h = 160;
  Scene s = empty_scene(w, h, {0, 0, 0}, {0, 0, -1}, 100);
  add_plane(s, {0, 0, -1.5f}, {0, 0, 1}, 50, emissive(s, {1, 0, 0}));
  add_box(s, {1, 1, 1}, 0.0f, glass(s, 1.5f));
  RenderOutput out = trace(s, 1);
  CameraFrame frame = make_camera_frame(s.camera, w, h);
  const float critical = std::asin(1.0f / 1.5f);
  int red = 0, reflected = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 d = glm::normalize(camera_ray_direction(frame, x + 0.5f, y + 0.5f));
      glm::vec3 on_face = d / -d.z;  // where it meets z = -1
      if (std::abs(on_face.x) > 0.98f || std::abs(on_face.y) > 0.98f) continue;  // other faces
      float angle = std::acos(-d.z);
      if (std::abs(angle - critical) < 0.01f) continue;  // a pixel on the boundary
      glm::vec3 c = out.buffers.colour[out.buffers.index(x, y)];
      if (angle < critical) {
        EXPECT_EQ(c, glm::vec3(1, 0, 0)) << x << "," << y;
        ++red;
      } else {
        EXPECT_EQ(c, glm::vec3(0.0f)) << x << "," << y;
        ++reflected;
      }
    }
  EXPECT_GT(red, 1000);
  EXPECT_GT(reflected, 1000);
}

namespace {
// Second moment of the image's brightness about its centroid, in pixels^2.
struct Blob {
  double total = 0, cx = 0, cy = 0, r2 = 0;
};
Blob measure(const FrameBuffers& fb) {
  Blob b;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x) {
      double v = fb.colour[fb.index(x, y)].x;
      b.total += v;
      b.cx += v * (x + 0.5);
      b.cy += v * (y + 0.5);
    }
  b.cx /= b.total;
  b.cy /= b.total;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x) {
      double v = fb.colour[fb.index(x, y)].x, dx = x + 0.5 - b.cx, dy = y + 0.5 - b.cy;
      b.r2 += v * (dx * dx + dy * dy);
    }
  b.r2 /= b.total;
  return b;
}
}  // namespace

// Thin lens: a point at depth D seen with aperture radius A focused at F blurs into a disc of
// radius f * A * |D - F| / (D * F) pixels (f: focal length in pixels). A uniform disc of radius
// R has mean squared radius R^2 / 2; the pixel's own box adds 1/6 and the small sphere's
// sharp image its own.
TEST(DepthOfField, BlurMatchesTheCircleOfConfusionAndTheFocusPlaneStaysSharp) {
  const int w = 96, h = 96;
  const float D = 4.0f, F = 8.0f, A = 0.15f, ball = 0.01f;
  Scene s = empty_scene(w, h, {0, 0, 0}, {0, 0, -1}, 20);
  s.camera.aperture_radius = A;
  s.camera.focus_distance = F;
  s.image.samples_per_pixel = 256;
  Object point;
  point.type = ObjectType::Sphere;
  point.sphere = {{0, 0, -D}, ball};
  point.material = emissive(s, {1, 1, 1});
  s.objects.push_back(point);
  CameraFrame frame = make_camera_frame(s.camera, w, h);
  const float focal_px = 0.5f * float(h) / frame.tan_half_fov_y;

  Blob blur = measure(trace(s).buffers);
  double sharp_r2 = 0.5 * std::pow(focal_px * ball / D, 2) + 1.0 / 6.0;
  double coc = focal_px * A * std::abs(D - F) / (D * F);
  double measured = std::sqrt(2.0 * (blur.r2 - sharp_r2));
  EXPECT_NEAR(measured, coc, 0.1 * coc) << "circle of confusion radius in pixels";
  std::printf("circle of confusion: measured radius %.3f px, thin-lens %.3f px (%+.1f%%)\n",
              measured, coc, 100.0 * (measured - coc) / coc);
  EXPECT_GT(coc, 5.0);  // a real blur, several pixels wide

  // The same point on the focus plane: no blur beyond the pixel and its own size.
  s.objects[0].sphere = {{0, 0, -F}, ball * F / D};
  Blob focused = measure(trace(s).buffers);
  EXPECT_LT(std::sqrt(2.0 * focused.r2), 0.2 * coc + 1.0);
}

namespace {
// A floor, a half-plane occluder at height `h_occ` covering x < 0, a square area light of
// side `size` at height H centred over x = 0. Returns the floor's brightness along the
// centre row as a function of the floor x.
struct ShadowRow {
  std::vector<glm::vec3> p;
  std::vector<float> x, brightness;
  std::vector<float> visible;  // brightness / brightness with no shadows
};
ShadowRow render_soft_shadow(float size, int samples, float H, float h_occ, int spp) {
  // The camera sits below the occluder, looking down at the floor line z = 0 (the centre row).
  const int w = 240, h = 24;
  Scene s = empty_scene(w, h, {0, 0.5f, 3}, {0, 0, 0}, 6);  // the row spans x in +-1.6
  Material floor;
  floor.diffuse = glm::vec3(1.0f);
  s.materials.push_back(floor);
  add_plane(s, {0, 0, 0}, {0, 1, 0}, 20, 1);
  Material black;
  black.diffuse = glm::vec3(0.0f);
  s.materials.push_back(black);
  add_plane(s, {-10, h_occ, 0}, {0, 1, 0}, 10, 2);
  Light l;
  l.type = LightType::Area;
  l.corner = {-size / 2, H, -size / 2};
  l.edge_u = {size, 0, 0};
  l.edge_v = {0, 0, size};
  l.intensity = glm::vec3(10.0f);
  l.samples = samples;
  s.lights.push_back(l);
  s.image.samples_per_pixel = spp;
  RenderOutput out = trace(s);
  s.objects.pop_back();  // the occluder: what the floor gets with no shadow
  RenderOutput unshadowed = trace(s);
  CameraFrame frame = make_camera_frame(s.camera, w, h);
  ShadowRow row;
  for (int x = 0; x < w; ++x) {
    size_t i = out.buffers.index(x, h / 2);
    if (out.buffers.object_id[i] != 0) continue;
    glm::vec3 p =
        s.camera.eye + out.buffers.depth[i] * camera_ray_direction(frame, x + 0.5f, h / 2 + 0.5f);
    row.p.push_back(p);
    row.x.push_back(p.x);
    row.brightness.push_back(out.buffers.colour[i].x);
    row.visible.push_back(out.buffers.colour[i].x / unshadowed.buffers.colour[i].x);
  }
  return row;
}

// Where the visible (weighted) fraction of the light rises from 5% to 95%.
float penumbra_width(const ShadowRow& row) {
  float lo = NAN, hi = NAN;
  for (size_t i = 0; i < row.x.size(); ++i) {
    if (std::isnan(lo) && row.visible[i] > 0.05f) lo = row.x[i];
    if (std::isnan(hi) && row.visible[i] > 0.95f) hi = row.x[i];
  }
  return hi - lo;
}
}  // namespace

// Similar triangles: an occluder edge at height h under a light of size L at height H casts a
// penumbra L * h / (H - h) wide on the floor.
TEST(SoftShadows, PenumbraWidthGrowsWithLightSizeAsGeometryPredicts) {
  const float H = 4.0f, h_occ = 1.0f;
  float previous = 0.0f;
  for (float size : {0.5f, 1.0f, 2.0f}) {
    ShadowRow row = render_soft_shadow(size, 16, H, h_occ, 1);
    float width = penumbra_width(row);
    float expected = size * h_occ / (H - h_occ);
    // 5%-95% of a nearly linear ramp is 90% of the full width; the samples quantise it to
    // 1/16 steps and the falloff over the light tilts it slightly: 15% covers both.
    EXPECT_NEAR(width, 0.9f * expected, 0.15f * expected) << "light size " << size;
    EXPECT_GT(width, previous);
    std::printf("penumbra for a light of size %.1f: %.4f (5%%-95%%), geometry %.4f x 0.9 = %.4f\n",
                size, width, expected, 0.9f * expected);
    previous = width;
  }
}

// At one floor point in the penumbra the visible part of the light is known exactly; the
// n x n stratified estimate must converge to the brightness integrated over the light.
TEST(SoftShadows, StratifiedSamplesConvergeToTheAnalyticOcclusion) {
  const float H = 4.0f, h_occ = 1.0f, size = 2.0f;
  // Reference: integrate the shading equation's kernel over the light on a fine grid with the
  // exact visibility of a half-plane edge (light point visible when the segment passes the
  // occluder's height at x >= 0).
  auto reference = [&](glm::vec3 p) {
    const int n = 600;
    double sum = 0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        glm::vec3 l(-size / 2 + size * (i + 0.5f) / n, H, -size / 2 + size * (j + 0.5f) / n);
        float x_at_occluder = p.x + (l.x - p.x) * h_occ / H;
        if (x_at_occluder < 0) continue;
        glm::vec3 d = l - p;
        float d2 = glm::dot(d, d);
        sum += std::max(0.0f, d.y / std::sqrt(d2)) / d2;
      }
    return float(sum * 10.0 / (double(n) * n));
  };
  float previous_error = INFINITY;
  for (int samples : {2, 4, 16}) {
    ShadowRow row = render_soft_shadow(size, samples, H, h_occ, 1);
    double error = 0;
    int count = 0;
    for (size_t i = 0; i < row.x.size(); i += 8) {
      if (std::abs(row.x[i]) > 0.6f) continue;  // inside the penumbra (about +-0.33 .. 0.33)
      error += std::abs(row.brightness[i] - reference(row.p[i]));
      ++count;
    }
    error /= count;
    EXPECT_LT(error, previous_error) << samples << "x" << samples;
    std::printf("%2dx%-2d light samples: mean |error| in the penumbra %.5f\n", samples, samples,
                error);
    previous_error = float(error);
  }
  float lit = reference({0.6f, 0.0f, 0.0f});  // just outside the penumbra
  EXPECT_LT(previous_error, 0.03f * lit);     // 16 x 16: within 3% of full brightness
}
