// Depth precision as a z-buffer format (--depth-format): two nearly coincident planes in front of
// the camera, A at view depth 10 and B behind it by delta(x), from 0.25 to 4 of d24's steps
// across the image, with near 0.05 and far 100. B is object 0 and drawn first, so where a format
// stores the same value for both, B keeps the pixel (the depth test is strict) and the ids
// differ from the tracer's, which sees A everywhere. What each format stores is worked out here
// from its definition (window z = f (d - n) / (d (f - n)); d24: round(z * (2^24 - 1)); d32f:
// float(z); reversed: float(n (f - d) / (d (f - n)))), at the analytic depths of the two planes.
#include <gtest/gtest.h>
#include <stddef.h>

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raster/soft_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"
#include "scene_builders.h"

namespace rvr {
namespace {

constexpr int kSize = 64;
constexpr double kNear = 0.05, kFar = 100.0, kDepthA = 10.0;
constexpr double kD24 = 16777215.0;  // 2^24 - 1
// One d24 step in view depth at depth 10: d^2 (f - n) / (f n M).
const double kStep = kDepthA * kDepthA * (kFar - kNear) / (kFar * kNear * kD24);

Object quad_object(const std::string& name, const std::vector<glm::vec3>& corners) {
  Object o;
  o.name = name;
  o.type = ObjectType::Triangles;
  o.material = 0;
  o.mesh.positions = corners;
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return o;
}

// B behind A by delta(X) = delta0 + g X at world x = X: 0.25 steps at the image's left edge,
// 4 at its right (the view spans x = +-10 tan 15 deg = +-2.68 at depth 10).
Scene two_planes() {
  Scene s = test::empty_scene(kSize, kSize, glm::vec3(0.0f), glm::vec3(0, 0, -1), 30.0f);
  s.camera.near = float(kNear);
  s.camera.far = float(kFar);
  const double half_view = kDepthA * std::tan(15.0 * 3.14159265358979 / 180.0);
  const double g = (4.0 - 0.25) * kStep / (2.0 * half_view);
  const double delta0 = 0.25 * kStep + g * half_view;
  auto zb = [&](double x) { return -float(kDepthA + delta0 + g * x); };
  s.objects.push_back(
      quad_object("B", {{-8, -8, zb(-8)}, {8, -8, zb(8)}, {8, 8, zb(8)}, {-8, 8, zb(-8)}}));
  const float za = -float(kDepthA);
  s.objects.push_back(quad_object("A", {{-8, -8, za}, {8, -8, za}, {8, 8, za}, {-8, 8, za}}));
  return s;
}

// The view depth of the plane through B's (float) corners along the ray through pixel column x.
double depth_of_b(const Scene& s, int x) {
  const Object& b = s.objects[0];
  const glm::dvec3 p0(b.mesh.positions[0]), p1(b.mesh.positions[1]), p3(b.mesh.positions[3]);
  const glm::dvec3 normal = glm::cross(p1 - p0, p3 - p0);
  const double tan_half = std::tan(double(s.camera.fov_y_deg) * 3.14159265358979 / 360.0);
  const double ndc_x = 2.0 * (x + 0.5) / kSize - 1.0;
  const glm::dvec3 dir(ndc_x * tan_half, 0.0, -1.0);    // y does not change B's depth
  return glm::dot(p0, normal) / glm::dot(dir, normal);  // unit component along the view axis
}

double window_z(double d) {
  return kFar * (d - kNear) / (d * (kFar - kNear));
}

struct Prediction {
  bool b_wins = false;  // the format stores the same value for A and B
  bool decided = true;  // no value within 1e-3 of a rounding boundary
  double steps = 0.0;   // (window z of B - of A) * (2^24 - 1)
};

Prediction predict(DepthFormat format, double da, double db) {
  Prediction p;
  p.steps = (window_z(db) - window_z(da)) * kD24;
  switch (format) {
    case DepthFormat::D24: {
      const double a = window_z(da) * kD24, b = window_z(db) * kD24;
      p.b_wins = std::floor(a + 0.5) == std::floor(b + 0.5);
      auto near_boundary = [](double v) { return std::fabs(v - std::floor(v) - 0.5) < 1e-3; };
      p.decided = !near_boundary(a) && !near_boundary(b);
      break;
    }
    case DepthFormat::D32F: {
      const float a = float(window_z(da)), b = float(window_z(db));
      p.b_wins = a == b;
      // Within 1e-3 ulp of a rounding boundary of float: undecided.
      const double ulp = std::ldexp(1.0, std::ilogb(window_z(db)) - 23);
      const double fb = window_z(db) / ulp, fa = window_z(da) / ulp;
      p.decided = std::fabs(fb - std::floor(fb) - 0.5) > 1e-3 &&
                  std::fabs(fa - std::floor(fa) - 0.5) > 1e-3;
      break;
    }
    case DepthFormat::D32FReversed: {
      auto reversed = [](double d) { return kNear * (kFar - d) / (d * (kFar - kNear)); };
      p.b_wins = float(reversed(da)) == float(reversed(db));
      break;
    }
  }
  return p;
}

RenderOutput render(Renderer& r, const Scene& s, std::optional<DepthFormat> format) {
  RenderOptions o;
  o.mode = RenderMode::Visibility;
  o.depth_format = format;
  auto out = r.render(s, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return out.ok() ? std::move(out.value()) : RenderOutput{};
}

// Pixels whose object id differs from the tracer's (which sees A, object 1, everywhere).
double mismatch_fraction(const FrameBuffers& fb) {
  size_t n = 0;
  for (uint32_t id : fb.object_id) n += id != 1u;
  return double(n) / double(fb.object_id.size());
}

class DepthFormatTest : public ::testing::Test {
 protected:
  Scene scene = two_planes();
};

TEST_F(DepthFormatTest, TheTracerSeesTheNearerPlaneEverywhere) {
  RayTracer tracer;
  RenderOutput t = render(tracer, scene, std::nullopt);
  ASSERT_EQ(t.buffers.object_id.size(), size_t(kSize * kSize));
  EXPECT_EQ(mismatch_fraction(t.buffers), 0.0);
  // The depths the predictions use are the tracer's to float precision (1e-6 relative).
  for (int x = 0; x < kSize; ++x) EXPECT_NEAR(t.buffers.depth[size_t(x)], kDepthA, 1e-5);
}

// softraster stores the exact depth as the format would: which plane wins is predicted for every
// pixel not within 1e-3 of a rounding boundary.
TEST_F(DepthFormatTest, SoftrasterWinsWhereTheFormatSaysD24AndD32f) {
  SoftRasterizer soft;
  for (DepthFormat format : {DepthFormat::D24, DepthFormat::D32F}) {
    SCOPED_TRACE(to_string(format));
    RenderOutput out = render(soft, scene, format);
    ASSERT_EQ(out.buffers.object_id.size(), size_t(kSize * kSize));
    EXPECT_EQ(out.info["depth_format"], to_string(format));
    size_t predicted_b = 0, decided = 0;
    for (int x = 0; x < kSize; ++x) {
      const Prediction p = predict(format, kDepthA, depth_of_b(scene, x));
      if (!p.decided) continue;
      ++decided;
      predicted_b += p.b_wins;
      for (int y = 0; y < kSize; ++y)
        EXPECT_EQ(out.buffers.object_id[size_t(y) * kSize + size_t(x)], p.b_wins ? 0u : 1u)
            << "pixel " << x << "," << y << " (" << p.steps << " steps apart)";
    }
    EXPECT_GE(decided, size_t(kSize - 2));
    // Measurable: B can tie only where the planes are under a step apart (steps 0.25 to 1: a
    // fifth of the columns), and there ties on about (1 - steps) of them: 0.375 of a fifth,
    // 7.5% of the image; at least 5% (3 of 64 columns) must show it.
    EXPECT_GE(double(predicted_b) / double(kSize), 0.05);
    EXPECT_GE(mismatch_fraction(out.buffers), 0.05);
  }
}

TEST_F(DepthFormatTest, ReversedFloatOrdersThePlanesLikeTheTracer) {
  for (int x = 0; x < kSize; ++x)
    ASSERT_FALSE(predict(DepthFormat::D32FReversed, kDepthA, depth_of_b(scene, x)).b_wins);
  SoftRasterizer soft;
  RenderOutput s = render(soft, scene, DepthFormat::D32FReversed);
  EXPECT_EQ(mismatch_fraction(s.buffers), 0.0);
  GlRasterizer gl;
  RenderOutput g = render(gl, scene, DepthFormat::D32FReversed);
  EXPECT_EQ(g.info["depth_format"], "d32f_reversed");
  EXPECT_EQ(mismatch_fraction(g.buffers), 0.0);
  // The default is the most precise: reversed float for GL, exact for softraster.
  EXPECT_EQ(mismatch_fraction(render(gl, scene, std::nullopt).buffers), 0.0);
  EXPECT_EQ(render(gl, scene, std::nullopt).info["depth_format"], "d32f_reversed");
  EXPECT_EQ(mismatch_fraction(render(soft, scene, std::nullopt).buffers), 0.0);
}

// GL's d24 fights where the planes are less than a step apart and agrees with softraster's d24
// where they are 2 steps apart or more (GL computes window z in float, whose rounding near 1 is
// 1 step of d24 or less, so one step of margin is left).
TEST_F(DepthFormatTest, GlD24FightsLikeSoftrasterD24) {
  GlRasterizer gl;
  SoftRasterizer soft;
  RenderOutput g = render(gl, scene, DepthFormat::D24);
  RenderOutput s = render(soft, scene, DepthFormat::D24);
  ASSERT_EQ(g.buffers.object_id.size(), size_t(kSize * kSize));
  EXPECT_EQ(g.info["depth_format"], "d24");
  size_t far_apart = 0, under_a_step = 0;
  for (int x = 0; x < kSize; ++x) {
    const Prediction p = predict(DepthFormat::D24, kDepthA, depth_of_b(scene, x));
    if (p.steps >= 2.0) {
      ++far_apart;
      for (int y = 0; y < kSize; ++y) {
        const size_t i = size_t(y) * kSize + size_t(x);
        EXPECT_EQ(g.buffers.object_id[i], 1u) << x << "," << y;
        EXPECT_EQ(g.buffers.object_id[i], s.buffers.object_id[i]) << x << "," << y;
      }
    }
    under_a_step += p.steps < 1.0;
  }
  EXPECT_GE(far_apart, size_t(kSize / 4));
  // Under a step apart (the first ~20% of the columns), the two planes share a d24 value or
  // neighbouring ones: GL shows B on a measurable share of the image, as softraster does.
  EXPECT_GE(under_a_step, size_t(kSize / 8));
  EXPECT_GE(mismatch_fraction(g.buffers), 0.05);
  // d32f (not reversed) has about the same resolution near window z 1 as d24 (its ulp there is
  // 2^-24): it fights too.
  EXPECT_GE(mismatch_fraction(render(gl, scene, DepthFormat::D32F).buffers), 0.05);
}

// The depth AOV is the linear view depth whatever the format.
TEST_F(DepthFormatTest, DepthAovIsTheViewDepthInEveryFormat) {
  GlRasterizer gl;
  SoftRasterizer soft;
  for (DepthFormat format : {DepthFormat::D24, DepthFormat::D32F, DepthFormat::D32FReversed})
    for (Renderer* r : {static_cast<Renderer*>(&gl), static_cast<Renderer*>(&soft)}) {
      RenderOutput out = render(*r, scene, format);
      for (size_t i = 0; i < out.buffers.depth.size(); ++i)
        ASSERT_NEAR(out.buffers.depth[i], kDepthA, 1e-3) << r->name() << " " << to_string(format);
    }
}

}  // namespace
}  // namespace rvr
