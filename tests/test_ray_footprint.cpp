// The ray footprint's transfers (raytrace/src/ray_footprint.h) against numerical derivatives:
// a family of rays O(x) = O0 + x dO, D(x) = D0 + x dD meets a plane, reflects and refracts, each
// worked out in double for x = +-h; the central differences must equal the differentials the
// footprint carries (Igehy's transfer, the mirror and refraction formulas differentiated).
#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <initializer_list>
#include <memory>

#include "ray_footprint.h"
#include "rvr/core/ray.h"

using namespace rvr;

namespace {

const glm::dvec3 kO0(0.3, 2.0, 1.5), kDO(0.02, -0.01, 0.03);
const glm::dvec3 kD0(0.2, -0.9, -0.4), kDD(0.05, 0.02, -0.03);
const glm::dvec3 kN = glm::normalize(glm::dvec3(0.1, 1.0, 0.2));  // the plane through Q
const glm::dvec3 kQ(0.0, 0.1, 0.0);
constexpr double kH = 1e-5;

glm::dvec3 origin(double x) {
  return kO0 + x * kDO;
}
glm::dvec3 direction(double x) {
  return kD0 + x * kDD;
}
double hit_t(double x) {
  return glm::dot(kQ - origin(x), kN) / glm::dot(direction(x), kN);
}
glm::dvec3 hit_point(double x) {
  return origin(x) + hit_t(x) * direction(x);
}
glm::dvec3 unit_direction(double x) {
  return glm::normalize(direction(x));
}
glm::dvec3 mirrored(double x) {
  const glm::dvec3 d = unit_direction(x);
  return d - 2.0 * glm::dot(d, kN) * kN;
}
// The tracer's refraction, entering (the ray meets the normal's side), N facing the viewer.
glm::dvec3 refracted(double x, double eta) {
  const glm::dvec3 d = unit_direction(x);
  const double cos_i = -glm::dot(d, kN);
  const double k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
  return eta * d + (eta * cos_i - std::sqrt(k)) * kN;
}

template <class F>
glm::dvec3 numerical(F f) {
  return (f(kH) - f(-kH)) / (2.0 * kH);
}

HitFootprint footprint_here() {
  RayFootprint ray;
  ray.dO_dx = glm::vec3(kDO);
  ray.dD_dx = glm::vec3(kDD);
  ray.cone_width = 0.01f;
  ray.cone_spread = 0.002f;
  return footprint_at_hit(ray, glm::vec3(kD0), float(hit_t(0.0)), glm::vec3(kN));
}

void expect_near(const glm::vec3& got, const glm::dvec3& want, const char* what) {
  // Central differences at h = 1e-5 are good to ~1e-9 here; the float pipeline to ~1e-6 of
  // the vectors' size (about 1).
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want[a], 1e-5) << what << " axis " << a;
}

}  // namespace

TEST(RayFootprint, TransferToTheHitIsTheDerivativeOfTheHitPoint) {
  const HitFootprint h = footprint_here();
  expect_near(h.dP_dx, numerical(hit_point), "dP/dx");
  expect_near(h.dd_dx, numerical(unit_direction), "d(normalize D)/dx");
  // The cone grows by its spread over the distance travelled.
  EXPECT_NEAR(h.cone_width, 0.01 + 0.002 * hit_t(0.0) * glm::length(kD0), 1e-7);
}

TEST(RayFootprint, ReflectionDifferentiatesTheMirrorFormula) {
  const RayFootprint r = reflected_footprint(footprint_here(), glm::vec3(kN));
  expect_near(r.dO_dx, numerical(hit_point), "reflected dO/dx");
  expect_near(r.dD_dx, numerical(mirrored), "reflected dD/dx");
}

TEST(RayFootprint, RefractionDifferentiatesTheRefractionFormula) {
  for (double eta : {1.0 / 1.5, 1.0 / 1.33, 1.2}) {
    const RayFootprint r = refracted_footprint(footprint_here(), glm::vec3(unit_direction(0.0)),
                                               glm::vec3(kN), float(eta));
    expect_near(r.dO_dx, numerical(hit_point), "refracted dO/dx");
    expect_near(r.dD_dx, numerical([eta](double x) { return refracted(x, eta); }),
                "refracted dD/dx");
    EXPECT_EQ(r.cone_width, footprint_here().cone_width);  // the cone carries on
  }
}
