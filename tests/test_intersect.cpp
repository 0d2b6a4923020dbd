// Ray-primitive tests against analytic answers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <initializer_list>
#include <random>
#include <string>

#include "rvr/core/ray.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/square.h"
#include "rvr/core/tessellate.h"
#include "rvr/raytrace/intersect.h"

using namespace rvr;

namespace {

Ray make_ray(glm::vec3 o, glm::vec3 d, float tmin = 0.0f, float tmax = INFINITY) {
  return Ray{o, d, tmin, tmax};
}

const TrianglePrecomputed kTri = precompute_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});

}  // namespace

TEST(Sphere, HitFromOutsideGivesNearRoot) {
  float t;
  ASSERT_TRUE(intersect_sphere(make_ray({0, 0, -5}, {0, 0, 1}), {{0, 0, 0}, 1}, t));
  EXPECT_FLOAT_EQ(t, 4.0f);
}

TEST(Sphere, NonUnitDirectionScalesT) {
  float t;
  ASSERT_TRUE(intersect_sphere(make_ray({0, 0, -5}, {0, 0, 2}), {{0, 0, 0}, 1}, t));
  EXPECT_FLOAT_EQ(t, 2.0f);
}

TEST(Sphere, InsideGivesFarRoot) {
  float t;
  ASSERT_TRUE(intersect_sphere(make_ray({0, 0, 0.5f}, {0, 0, 1}), {{0, 0, 0}, 1}, t));
  EXPECT_FLOAT_EQ(t, 0.5f);
  ASSERT_TRUE(intersect_sphere(make_ray({0, 0, 0.5f}, {0, 0, -1}), {{0, 0, 0}, 1}, t));
  EXPECT_FLOAT_EQ(t, 1.5f);
}

TEST(Sphere, BehindTheOriginIsMissed) {
  float t;
  EXPECT_FALSE(intersect_sphere(make_ray({0, 0, 0}, {0, 0, 1}), {{0, 0, -5}, 1}, t));
}

TEST(Sphere, GrazingRays) {
  float t;
  // Just inside the silhouette: hits near the tangent point x = 0.9999, z ~ 0.
  ASSERT_TRUE(intersect_sphere(make_ray({0.9999f, 0, -5}, {0, 0, 1}), {{0, 0, 0}, 1}, t));
  EXPECT_NEAR(t, 5.0f - std::sqrt(1.0f - 0.9999f * 0.9999f), 1e-4f);
  EXPECT_FALSE(intersect_sphere(make_ray({1.0001f, 0, -5}, {0, 0, 1}), {{0, 0, 0}, 1}, t));
}

TEST(Sphere, SmallFarSphereKeepsPrecision) {
  // The textbook b^2 - 4ac loses every digit here; the stable form does not.
  float t;
  ASSERT_TRUE(intersect_sphere(make_ray({0, 0, 0}, {0, 0, -1}), {{0, 0, -10000}, 0.01f}, t));
  EXPECT_NEAR(t, 9999.99f, 2e-3f);
}

TEST(Sphere, RespectsTmaxAndTmin) {
  float t;
  EXPECT_FALSE(intersect_sphere(make_ray({0, 0, -5}, {0, 0, 1}, 0, 3.9f), {{0, 0, 0}, 1}, t));
  ASSERT_TRUE(intersect_sphere(make_ray({0, 0, -5}, {0, 0, 1}, 4.5f), {{0, 0, 0}, 1}, t));
  EXPECT_FLOAT_EQ(t, 6.0f);  // near root below tmin: the far one counts
}

TEST(Square, HitInsideAndMissOutside) {
  Square p{{0, 0, 0}, {0, 1, 0}, 1.0f};
  auto [u, v] = plane_axes(p.normal);
  float t;
  ASSERT_TRUE(intersect_square(make_ray({0.5f, 2, 0.5f}, {0, -1, 0}), p, u, v, t));
  EXPECT_FLOAT_EQ(t, 2.0f);
  EXPECT_FALSE(intersect_square(make_ray({1.5f, 2, 0}, {0, -1, 0}), p, u, v, t));
  // Exactly on the boundary counts as inside.
  EXPECT_TRUE(intersect_square(make_ray({1.0f, 2, 0}, {0, -1, 0}), p, u, v, t));
}

TEST(Square, ParallelAndBehindAreMissed) {
  Square p{{0, 0, 0}, {0, 1, 0}, 1.0f};
  auto [u, v] = plane_axes(p.normal);
  float t;
  EXPECT_FALSE(intersect_square(make_ray({0, 1, 0}, {1, 0, 0}), p, u, v, t));
  EXPECT_FALSE(intersect_square(make_ray({0, 1, 0}, {0, 1, 0}), p, u, v, t));
  // From below, facing away from the normal, still hits: planes are two-sided.
  EXPECT_TRUE(intersect_square(make_ray({0, -1, 0}, {0, 1, 0}), p, u, v, t));
  EXPECT_FLOAT_EQ(t, 1.0f);
}

TEST(PlaneAxes, OrthonormalAndRightHanded) {
  for (glm::vec3 n : {glm::vec3(0, 1, 0), glm::vec3(0, 0, 1), glm::vec3(1, 0, 0),
                      glm::normalize(glm::vec3(1, 2, 3)), glm::vec3(0, -1, 0)}) {
    auto [u, v] = plane_axes(n);
    EXPECT_NEAR(glm::length(u), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::length(v), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(u, v), 0.0f, 1e-6f);
    glm::vec3 c = glm::cross(u, v);
    EXPECT_NEAR(glm::distance(c, n), 0.0f, 1e-6f);
  }
}

template <class Test>
void check_triangle_cases(Test test) {
  TriangleHit h;
  // Interior point (0.25, 0.25): u = 0.25, v = 0.25, t = 2.
  ASSERT_TRUE(test(make_ray({0.25f, 0.25f, 2}, {0, 0, -1}), kTri, h));
  EXPECT_FLOAT_EQ(h.t, 2.0f);
  EXPECT_FLOAT_EQ(h.u, 0.25f);
  EXPECT_FLOAT_EQ(h.v, 0.25f);
  // Edge and vertex hits count.
  ASSERT_TRUE(test(make_ray({0.5f, 0.5f, 1}, {0, 0, -1}), kTri, h));
  EXPECT_NEAR(h.u + h.v, 1.0f, 1e-6f);
  ASSERT_TRUE(test(make_ray({0.5f, 0.0f, 1}, {0, 0, -1}), kTri, h));
  EXPECT_NEAR(h.v, 0.0f, 1e-7f);
  ASSERT_TRUE(test(make_ray({0, 0, 1}, {0, 0, -1}), kTri, h));
  ASSERT_TRUE(test(make_ray({1, 0, 1}, {0, 0, -1}), kTri, h));
  // Outside, parallel, behind the origin, beyond tmax.
  EXPECT_FALSE(test(make_ray({0.6f, 0.6f, 1}, {0, 0, -1}), kTri, h));
  EXPECT_FALSE(test(make_ray({-0.01f, 0.5f, 1}, {0, 0, -1}), kTri, h));
  EXPECT_FALSE(test(make_ray({0.2f, 0.2f, 1}, {1, 0, 0}), kTri, h));
  EXPECT_FALSE(test(make_ray({0.2f, 0.2f, 1}, {0, 0, 1}), kTri, h));
  EXPECT_FALSE(test(make_ray({0.2f, 0.2f, 1}, {0, 0, -1}, 0, 0.5f), kTri, h));
  // Back side: triangles are two-sided.
  ASSERT_TRUE(test(make_ray({0.2f, 0.2f, -1}, {0, 0, 1}), kTri, h));
  EXPECT_FLOAT_EQ(h.t, 1.0f);
}

TEST(Triangle, MollerTrumboreAnalyticCases) {
  check_triangle_cases(intersect_triangle_mt);
}
TEST(Triangle, ChapterTestAnalyticCases) {
  check_triangle_cases(intersect_triangle_chapter);
}

TEST(Triangle, TheTwoTestsAgreeOnRandomRays) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> U(-2.0f, 2.0f);
  int hits = 0, disagreements_off_edge = 0;
  for (int i = 0; i < 100000; ++i) {
    TrianglePrecomputed tri = precompute_triangle(
        {U(rng), U(rng), U(rng)}, {U(rng), U(rng), U(rng)}, {U(rng), U(rng), U(rng)});
    Ray ray = make_ray({U(rng), U(rng), U(rng) + 4}, {U(rng) * 0.3f, U(rng) * 0.3f, -1});
    TriangleHit a, b;
    bool ha = intersect_triangle_mt(ray, tri, a);
    bool hb = intersect_triangle_chapter(ray, tri, b);
    if (ha && hb) {
      ++hits;
      EXPECT_NEAR(a.t, b.t, 1e-4f * std::max(1.0f, std::abs(a.t)));
      EXPECT_NEAR(a.u, b.u, 1e-3f);
      EXPECT_NEAR(a.v, b.v, 1e-3f);
    } else if (ha != hb) {
      // Rounding may put a point on an edge on either side: only hits within a hair of an
      // edge (a barycentric within 1e-4 of 0) may disagree.
      const TriangleHit& h = ha ? a : b;
      float margin = std::min({h.u, h.v, 1.0f - h.u - h.v});
      if (margin > 1e-4f) ++disagreements_off_edge;
    }
  }
  EXPECT_GT(hits, 3000);  // enough hits for the comparison to mean something
  EXPECT_EQ(disagreements_off_edge, 0);
}

TEST(Triangle, SharedEdgeIsNeverLeaking) {
  // Two triangles of a square; rays through the diagonal must hit at least one.
  TrianglePrecomputed a = precompute_triangle({0, 0, 0}, {1, 0, 0}, {1, 1, 0});
  TrianglePrecomputed b = precompute_triangle({0, 0, 0}, {1, 1, 0}, {0, 1, 0});
  for (int i = 0; i <= 1000; ++i) {
    float s = float(i) / 1000.0f;
    Ray r = make_ray({s, s, 1}, {0.0001f * s, -0.0002f, -1});
    TriangleHit h;
    bool hit = intersect_triangle_mt(r, a, h) || intersect_triangle_mt(r, b, h);
    glm::vec3 p = r.origin + r.dir;  // where it meets z = 0
    if (p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1) {
      EXPECT_TRUE(hit) << "s = " << s;
    }
  }
}
