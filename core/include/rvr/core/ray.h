// A ray, and what an analytic shape's ray test reports: the shapes' intersections (shapes/*.h)
// and the tracers' triangle tests (rvr/raytrace/intersect.h) take it.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>

namespace rvr {

struct Ray {
  glm::vec3 origin;
  glm::vec3 dir;  // need not be unit length; t is measured in units of |dir|
  float tmin = 0.0f;
  float tmax = INFINITY;
};

// An analytic shape's hit: t in (tmin, tmax); `part` and `flip` say which surface of a shape
// made of several was hit (a CSG solid's leaf sphere; a subtracted one's normal is reversed).
struct ShapeHit {
  float t = INFINITY;
  uint32_t part = 0;
  bool flip = false;
};

}  // namespace rvr
