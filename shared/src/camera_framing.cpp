// A camera that frames the scene's geometry (see camera_framing.h).
#include "rvr/shared/camera_framing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "rvr/shared/tessellate.h"

namespace rvr {
namespace {

void grow(glm::vec3& lo, glm::vec3& hi, const glm::vec3& p) {
  lo = glm::min(lo, p);
  hi = glm::max(hi, p);
}

void csg_points(const CsgNode* node, std::vector<std::pair<glm::vec3, float>>& balls) {
  if (!node) return;
  if (node->is_leaf) {
    balls.emplace_back(node->sphere.center, node->sphere.radius);
    return;
  }
  csg_points(node->a.get(), balls);
  csg_points(node->b.get(), balls);
}

// Every object as points with a radius (0 for vertices).
std::vector<std::pair<glm::vec3, float>> scene_points(const Scene& scene) {
  std::vector<std::pair<glm::vec3, float>> points;
  for (const Object& o : scene.objects) {
    switch (o.type) {
      case ObjectType::Triangles:
        for (const glm::vec3& p : o.mesh.positions) points.emplace_back(p, 0.0f);
        break;
      case ObjectType::Sphere:
        points.emplace_back(o.sphere.center, o.sphere.radius);
        break;
      case ObjectType::Plane:
        for (const glm::vec3& p : plane_corners(o.plane)) points.emplace_back(p, 0.0f);
        break;
      case ObjectType::Csg:
        csg_points(o.csg.get(), points);
        break;
    }
  }
  return points;
}

}  // namespace

BoundingSphere scene_bounds(const Scene& scene) {
  std::vector<std::pair<glm::vec3, float>> points = scene_points(scene);
  BoundingSphere b;
  if (points.empty()) return b;
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const auto& [p, r] : points) {
    grow(lo, hi, p - glm::vec3(r));
    grow(lo, hi, p + glm::vec3(r));
  }
  b.centre = 0.5f * (lo + hi);
  float radius = 0.0f;
  for (const auto& [p, r] : points) radius = std::max(radius, glm::length(p - b.centre) + r);
  b.radius = radius > 0.0f ? radius : 1.0f;  // a single point: a unit sphere round it
  b.empty = false;
  return b;
}

glm::vec3 default_view_from() {
  const float azimuth = glm::radians(35.0f), elevation = glm::radians(30.0f);
  return {std::sin(azimuth) * std::cos(elevation), std::sin(elevation),
          std::cos(azimuth) * std::cos(elevation)};
}

void frame_camera(Scene& scene, const BoundingSphere& bounds, glm::vec3 from) {
  glm::vec3 dir = glm::normalize(from);
  Camera& c = scene.camera;
  float aspect = float(scene.image.width) / float(scene.image.height);
  float tan_half_y = std::tan(glm::radians(c.fov_y_deg) * 0.5f);
  // The narrower of the two half-angles must hold the sphere: sin(half) = radius / distance.
  float half = std::atan(tan_half_y * std::min(1.0f, aspect));
  float distance = 1.1f * bounds.radius / std::sin(half);
  c.target = bounds.centre;
  c.eye = bounds.centre + dir * distance;
  glm::vec3 up(0.0f, 1.0f, 0.0f);
  if (glm::length(glm::cross(dir, up)) < 1e-3f) up = glm::vec3(0.0f, 0.0f, -dir.y);
  c.up = up;
  // The sphere lies between distance - radius and distance + radius from the eye.
  c.near = std::max(0.5f * (distance - bounds.radius), 1e-4f * bounds.radius);
  c.far = distance + 2.0f * bounds.radius;
  c.aperture_radius = 0.0f;
  c.focus_distance = distance;
}

}  // namespace rvr
