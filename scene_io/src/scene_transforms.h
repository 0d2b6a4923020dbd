// An object's `transform` (scale, rotate_deg, translate) as a matrix, and moving values through
// it. Private to scene_io/src.
#pragma once

#include <cmath>
#include <glm/glm.hpp>
#include <string>

#include "scene_json_errors.h"

namespace rvr::scene_load {

struct Transform {
  bool identity = true;
  glm::dvec3 scale{1.0};
  glm::dmat4 matrix{1.0};
  glm::dmat3 normal_matrix{1.0};

  bool uniform() const {
    double s = std::abs(scale.x);
    return std::abs(scale.y) == s && std::abs(scale.z) == s;
  }
  glm::dvec3 point(const glm::dvec3& p) const { return glm::dvec3(matrix * glm::dvec4(p, 1.0)); }
  glm::dvec3 normal(const glm::dvec3& n) const { return normal_matrix * n; }
};

Transform parse_transform(const json& v, const std::string& path);
// Back to floats; fails if the transform took a value out of their range.
glm::vec3 to_float(const glm::dvec3& v, const std::string& path, const std::string& what);

}  // namespace rvr::scene_load
