// Small scenes built by hand for tests whose answers are worked out in closed form.
#pragma once

#include <gtest/gtest.h>

#include <cmath>

#include "rvr/core/scene.h"

namespace rvr::test {

inline Scene empty_scene(int w, int h, glm::vec3 eye, glm::vec3 target, float fov) {
  Scene s;
  s.source = "test";
  s.materials.push_back(default_material());
  s.image.width = w;
  s.image.height = h;
  s.camera.eye = eye;
  s.camera.target = target;
  s.camera.fov_y_deg = fov;
  s.camera.near = 0.01f;
  s.camera.far = 100.0f;
  s.camera.focus_distance = glm::length(target - eye);
  return s;
}

inline uint32_t add_material(Scene& s, glm::vec3 diffuse, glm::vec3 emission = glm::vec3(0.0f),
                             float mirror = 0.0f) {
  Material m;
  m.diffuse = diffuse;
  m.emission = emission;
  m.mirror = mirror;
  s.materials.push_back(m);
  return uint32_t(s.materials.size() - 1);
}

// Pure emission: its colour shows exactly, whatever the lights.
inline uint32_t emissive(Scene& s, glm::vec3 colour) {
  return add_material(s, glm::vec3(0.0f), colour);
}

// Fully transparent, no surface colour of its own.
inline uint32_t glass(Scene& s, float ior) {
  uint32_t m = add_material(s, glm::vec3(0.0f));
  s.materials[m].transparency = 1.0f;
  s.materials[m].ior = ior;
  return m;
}

inline void add_plane(Scene& s, glm::vec3 point, glm::vec3 normal, float half, uint32_t material) {
  Object o;
  o.type = ObjectType::Plane;
  o.plane = {point, glm::normalize(normal), half};
  o.material = material;
  s.objects.push_back(o);
}

inline void add_sphere(Scene& s, glm::vec3 c, float r, uint32_t material) {
  Object o;
  o.type = ObjectType::Sphere;
  o.sphere = {c, r};
  o.material = material;
  s.objects.push_back(o);
}

// A closed box with outward-facing (counter-clockwise from outside) triangles, rotated by
// `angle` radians about y.
inline void add_box(Scene& s, glm::vec3 half, float angle, uint32_t material) {
  Object o;
  o.type = ObjectType::Triangles;
  o.material = material;
  float c = std::cos(angle), sn = std::sin(angle);
  for (int i = 0; i < 8; ++i) {
    glm::vec3 p((i & 1 ? 1 : -1) * half.x, (i & 2 ? 1 : -1) * half.y, (i & 4 ? 1 : -1) * half.z);
    o.mesh.positions.push_back({c * p.x + sn * p.z, p.y, -sn * p.x + c * p.z});
  }
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 4, 6, 2},
                           {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}};
  for (const auto& q : quads) {
    o.mesh.triangles.push_back({uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2])});
    o.mesh.triangles.push_back({uint32_t(q[0]), uint32_t(q[2]), uint32_t(q[3])});
  }
  // The winding matters (entering vs leaving glass): every face normal points outwards.
  for (const glm::uvec3& t : o.mesh.triangles) {
    glm::vec3 a = o.mesh.positions[t.x], b = o.mesh.positions[t.y], d = o.mesh.positions[t.z];
    EXPECT_GT(glm::dot(glm::cross(b - a, d - a), (a + b + d) / 3.0f), 0.0f);
  }
  s.objects.push_back(o);
}

}  // namespace rvr::test
