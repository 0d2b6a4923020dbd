// CSG in both z-buffers (raster/src/csg_leaves.h; softraster's raster/src/soft/csg_pass.h,
// raster's resolve_csg in raster/src/gl_rasterizer.cpp): a difference of two spheres against its
// closed form, and builtin:csg against the tracer intersecting the same tessellated leaves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/camera.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raster/soft_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/scene_io/scene_loader.h"
#include "scene_builders.h"

namespace rvr {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Both roots of |o + t d - c|^2 = r^2 in double precision, the line's whole interval.
std::optional<std::pair<double, double>> line_sphere(const glm::dvec3& o, const glm::dvec3& d,
                                                     const glm::dvec3& c, double r) {
  const glm::dvec3 f = o - c;
  const double a = glm::dot(d, d), b = glm::dot(f, d), q = glm::dot(f, f) - r * r;
  const double disc = b * b - a * q;
  if (disc <= 0.0) return std::nullopt;
  const double s = std::sqrt(disc);
  return std::pair{(-b - s) / a, (-b + s) / a};
}

// Distance from centre c to the line o + t d.
double line_distance(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& c) {
  return glm::length(glm::cross(c - o, d)) / glm::length(d);
}

// The z-buffer named `zbuffer` (softraster or raster, on OSMesa) with tessellated spheres.
Expected<RenderOutput> render_zbuffer(const std::string& zbuffer, const Scene& scene,
                                      RenderMode mode, int segments) {
  RenderOptions options;
  options.mode = mode;
  options.sphere_segments = segments;
  options.spheres = SphereMode::Mesh;
  if (zbuffer == "raster") {
    GlRasterizer gl(GlBackend::OsMesa);
    return gl.render(scene, options);
  }
  SoftRasterizer soft;
  return soft.render(scene, options);
}

class CsgZBuffer : public ::testing::TestWithParam<std::string> {};

// A − B, sphere A (centre 0, radius 1) with sphere B (centre (0.35, 0.2, 0.55), radius 0.7)
// cut out of its front, seen from z = 5, partly behind a square. At each pixel the first
// surface of the solid along the centre ray is A's front where B does not hold it, else B's
// back where B ends inside A, else none: the z-buffer's depth there, its normal and its id must
// be that surface's, except where the square, nearer, hides it.
//
// Tolerances, from the tessellation (256 longitudes): every triangle's vertices lie on its
// sphere, and the triangle spans at most sqrt(2) * 2 pi / 256 of arc, so the surface drawn lies
// within r (1 - cos(sqrt(2) * 2 pi / 256)) = 6.0e-4 r of the sphere along its normal, and its
// interpolated normals within that arc of the sphere's. Pixels are compared where the ray
// meets the surface no more obliquely than 60 degrees (its depth error at most twice the
// radial one), away from the silhouettes' band of either sphere (where the ray's distance to
// the centre lies between r cos(arc) and r: the tessellation may hit or miss there) and away
// from where the closed form's case changes within the tolerance.
TEST_P(CsgZBuffer, DifferenceOfTwoSpheresHasItsClosedFormDepthNormalAndId) {
  Scene scene = test::empty_scene(96, 96, {0, 0, 5}, {0, 0, 0}, 30.0f);
  const glm::dvec3 ca(0.0), cb(0.35, 0.2, 0.55);
  const double ra = 1.0, rb = 0.7;
  auto a = std::make_shared<CsgNode>();
  a->sphere = {glm::vec3(ca), float(ra)};
  auto b = std::make_shared<CsgNode>();
  b->sphere = {glm::vec3(cb), float(rb)};
  auto root = std::make_shared<CsgNode>();
  root->is_leaf = false;
  root->op = CsgOp::Difference;
  root->a = a;
  root->b = b;
  Object o;
  o.type = ObjectType::Csg;
  o.csg = root;
  o.material = 0;
  scene.objects.push_back(o);
  // A square in front of part of it, drawn before it: where the square is, the solid is hidden.
  const glm::dvec3 square_centre(-0.45, -0.5, 2.0);
  const double square_half = 0.3;
  test::add_plane(scene, glm::vec3(square_centre), {0, 0, 1}, float(square_half), 0);
  std::swap(scene.objects[0], scene.objects[1]);
  const uint32_t solid = 1, square = 0;

  constexpr int kSegments = 256;
  const double arc = std::sqrt(2.0) * 2.0 * kPi / kSegments;
  const double radial = 1.0 - std::cos(arc);  // per unit radius
  Expected<RenderOutput> out = render_zbuffer(GetParam(), scene, RenderMode::Local, kSegments);
  ASSERT_TRUE(out.ok()) << out.error().message;
  const FrameBuffers& fb = out->buffers;
  const CameraFrame frame = make_camera_frame(scene.camera, fb.width, fb.height);
  const glm::dvec3 eye(scene.camera.eye);

  size_t front = 0, cut = 0, empty = 0, hidden = 0;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x) {
      const size_t i = size_t(y) * size_t(fb.width) + size_t(x);
      // Forward component 1: t along d is the view depth.
      const glm::dvec3 d(camera_ray_direction(frame, float(x) + 0.5f, float(y) + 0.5f));
      // The square, whatever its turn in its plane: inside the disc it contains, outside the
      // disc that contains it.
      const double t_square = (square_centre.z - eye.z) / d.z;
      const double off = glm::length(eye + t_square * d - square_centre);
      if (off < square_half * 0.95) {
        EXPECT_EQ(fb.object_id[i], square) << x << "," << y;
        EXPECT_NEAR(fb.depth[i], t_square, 1e-4) << x << "," << y;
        hidden++;
        continue;
      }
      if (off < square_half * std::sqrt(2.0) * 1.05) continue;
      const double da = line_distance(eye, d, ca), db = line_distance(eye, d, cb);
      if ((da > ra * std::cos(arc) && da <= ra) || (db > rb * std::cos(arc) && db <= rb))
        continue;  // a silhouette's band
      const auto ia = line_sphere(eye, d, ca, ra), ib = line_sphere(eye, d, cb, rb);
      if (!ia) {
        EXPECT_EQ(fb.object_id[i], kNoId) << x << "," << y;
        empty++;
        continue;
      }
      // The first point of A's interval outside B's.
      std::optional<double> t;
      glm::dvec3 centre = ca;
      double sign = 1.0, r = ra;
      if (!ib || ib->second <= ia->first || ib->first >= ia->first) {
        t = ia->first;
      } else if (ib->second < ia->second) {
        t = ib->second;
        centre = cb;
        sign = -1.0;  // B's back, seen from inside B: its inward normal
        r = rb;
      }
      const double tol = 2.0 * radial * std::max(ra, rb) * glm::length(d);
      bool near_a_case_change = false;
      for (double u : {ia->first, ia->second})
        if (ib)
          for (double v : {ib->first, ib->second})
            near_a_case_change |= std::abs(u - v) < 4.0 * tol;
      if (near_a_case_change) continue;
      if (!t) {
        EXPECT_EQ(fb.object_id[i], kNoId) << x << "," << y << ": A lies inside B there";
        empty++;
        continue;
      }
      const glm::dvec3 p = eye + *t * d;
      const glm::dvec3 n = sign * (p - centre) / r;
      if (glm::dot(n, -glm::normalize(d)) < 0.5) continue;  // more oblique than 60 degrees
      ASSERT_EQ(fb.object_id[i], solid) << x << "," << y;
      EXPECT_NEAR(fb.depth[i], *t, tol) << x << "," << y << (sign > 0 ? " (A's front)" : " (B)");
      EXPECT_GT(glm::dot(glm::dvec3(fb.normal[i]), n), std::cos(2.0 * arc))
          << x << "," << y << (sign > 0 ? " (A's front)" : " (B's back)");
      (sign > 0 ? front : cut)++;
    }
  // Each case is seen at many pixels.
  EXPECT_GT(front, 500u);
  EXPECT_GT(cut, 500u);
  EXPECT_GT(empty, 500u);
  EXPECT_GT(hidden, 100u);
}

// builtin:csg (union, intersection, difference and a nested tree on a floor) against the tracer
// with --spheres mesh, which intersects the same tessellated leaves (core/src/shapes/csg.cpp)
// and interpolates their normals: the loop orders sample the same pixel centres on the same
// triangles, so, as in test_conformance, ids agree but for fill-rule ties (>= 0.999; measured
// 1.0 at 320x240), depths to 1e-3 relative (measured 8e-6) and, away from id edges, colours to
// 1e-3 per channel (the conformance bound; measured 2.5e-5).
TEST_P(CsgZBuffer, AgreesWithTheTracerOnTheSameTessellatedLeaves) {
  Expected<Scene> loaded = make_builtin_scene("csg");
  ASSERT_TRUE(loaded.ok());
  Scene scene = *loaded;
  scene.image.width = 240;
  scene.image.height = 180;
  constexpr int kSegments = 48;
  Expected<RenderOutput> drawn = render_zbuffer(GetParam(), scene, RenderMode::Local, kSegments);
  RenderOptions options;
  options.mode = RenderMode::Local;
  options.sphere_segments = kSegments;
  options.spheres = SphereMode::Mesh;
  RayTracer tracer;
  Expected<RenderOutput> traced = tracer.render(scene, options);
  ASSERT_TRUE(drawn.ok() && traced.ok());
  const FrameBuffers &z = drawn->buffers, &t = traced->buffers;
  const int w = z.width, h = z.height;
  size_t agree = 0, csg = 0, compared_colour = 0;
  double worst_depth = 0.0, worst_colour = 0.0;
  auto id_at = [&](const FrameBuffers& f, int x, int y) {
    return f.object_id[size_t(y) * size_t(w) + size_t(x)];
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (z.object_id[i] != t.object_id[i]) continue;
      agree++;
      if (t.object_id[i] == kNoId || scene.objects[t.object_id[i]].type != ObjectType::Csg)
        continue;
      csg++;
      worst_depth = std::max(
          worst_depth, std::abs(double(z.depth[i]) - double(t.depth[i])) / double(t.depth[i]));
      bool edge = x == 0 || y == 0 || x == w - 1 || y == h - 1;
      for (int dy = -1; dy <= 1 && !edge; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          edge |= id_at(z, x + dx, y + dy) != z.object_id[i] ||
                  id_at(t, x + dx, y + dy) != t.object_id[i];
      if (edge) continue;
      compared_colour++;
      const glm::vec3 diff = glm::abs(z.colour[i] - t.colour[i]);
      worst_colour = std::max(worst_colour, double(std::max({diff.x, diff.y, diff.z})));
    }
  EXPECT_GE(double(agree) / double(w * h), 0.999);
  EXPECT_GT(csg, size_t(w * h) / 20);  // the CSG objects cover a good part of the frame
  EXPECT_GT(compared_colour, csg / 2);
  EXPECT_LE(worst_depth, 1e-3);
  EXPECT_LE(worst_colour, 1e-3);
}

INSTANTIATE_TEST_SUITE_P(BothZBuffers, CsgZBuffer, ::testing::Values("softraster", "raster"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

}  // namespace
}  // namespace rvr
