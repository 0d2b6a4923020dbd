// An object's `transform` (see scene_transforms.h).
#include "scene_transforms.h"

#include <glm/gtc/matrix_transform.hpp>

#include "json_fields.h"

namespace rvr::scene_load {

Transform parse_transform(const json& v, const std::string& path) {
  check_object(v, path);
  check_keys(v, path, {"scale", "rotate_deg", "translate"});
  Transform t;
  glm::dvec3 rotate{0.0}, translate{0.0};
  if (const json* s = find(v, "scale")) {
    std::string p = key_path(path, "scale");
    if (s->is_number()) {
      t.scale = glm::dvec3(real(*s, p));
      if (t.scale.x == 0.0) fail(p, "must be non-zero, got 0");
    } else if (s->is_array()) {
      t.scale = glm::dvec3(vec3(*s, p));
      for (int i = 0; i < 3; ++i) {
        if (t.scale[i] == 0.0) fail(index_path(p, i), "must be non-zero, got 0");
      }
    } else {
      fail(p, "must be a number or an array of 3 numbers, got " + describe(*s));
    }
  }
  if (const json* r = find(v, "rotate_deg")) rotate = vec3(*r, key_path(path, "rotate_deg"));
  if (const json* tr = find(v, "translate")) translate = vec3(*tr, key_path(path, "translate"));

  glm::dmat4 m = glm::translate(glm::dmat4(1.0), translate);
  m = glm::rotate(m, glm::radians(rotate.z), glm::dvec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(rotate.y), glm::dvec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(rotate.x), glm::dvec3(1, 0, 0));
  m = glm::scale(m, t.scale);
  t.matrix = m;
  t.normal_matrix = glm::transpose(glm::inverse(glm::dmat3(m)));
  t.identity =
      t.scale == glm::dvec3(1.0) && rotate == glm::dvec3(0.0) && translate == glm::dvec3(0.0);
  return t;
}

glm::vec3 to_float(const glm::dvec3& v, const std::string& path, const std::string& what) {
  glm::vec3 f(v);
  if (!std::isfinite(f.x) || !std::isfinite(f.y) || !std::isfinite(f.z)) {
    fail(path, what + " is out of range for 32-bit floats after the transform");
  }
  return f;
}

}  // namespace rvr::scene_load
