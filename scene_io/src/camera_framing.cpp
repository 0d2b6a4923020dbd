// A camera that frames the scene's geometry (see camera_framing.h).
#include "rvr/scene_io/camera_framing.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "rvr/core/shapes.h"
#include "rvr/core/shapes/shape_geometry.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {
namespace {

void grow(glm::vec3& lo, glm::vec3& hi, const glm::vec3& p) {
  lo = glm::min(lo, p);
  hi = glm::max(hi, p);
}

// Every object as balls that bound it.
std::vector<BoundingBall> scene_points(const Scene& scene) {
  std::vector<BoundingBall> points;
  for (const Object& o : scene.objects)
    visit_shape(o, [&](const auto& shape) { shape.bounding_balls(points); });
  return points;
}

}  // namespace

BoundingSphere scene_bounds(const Scene& scene) {
  std::vector<BoundingBall> points = scene_points(scene);
  BoundingSphere b;
  if (points.empty()) return b;
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const BoundingBall& ball : points) {
    grow(lo, hi, ball.centre - glm::vec3(ball.radius));
    grow(lo, hi, ball.centre + glm::vec3(ball.radius));
  }
  b.centre = 0.5f * (lo + hi);
  float radius = 0.0f;
  for (const BoundingBall& ball : points)
    radius = std::max(radius, glm::length(ball.centre - b.centre) + ball.radius);
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

ViewOfModel view_of_model(const Scene& scene, const Camera& camera, float aspect) {
  const glm::dvec3 eye(camera.eye);
  const glm::dvec3 f = glm::normalize(glm::dvec3(camera.target) - eye);
  const glm::dvec3 x = glm::normalize(glm::cross(f, glm::dvec3(camera.up)));
  const glm::dvec3 y = glm::cross(x, f);
  const double tan_y = std::tan(glm::radians(double(camera.fov_y_deg)) * 0.5);
  const double tan_x = tan_y * double(aspect);
  double total = 0.0;
  for (const Object& o : scene.objects) {
    if (o.type != ObjectType::Triangles) continue;
    for (const auto& t : o.mesh.triangles) {
      const glm::dvec3 a(o.mesh.positions[t[0]]), b(o.mesh.positions[t[1]]),
          c(o.mesh.positions[t[2]]);
      total += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
  }
  ViewOfModel view;
  if (!(total > 0.0) || !std::isfinite(total)) return view;
  // Screen coordinates run from -1 to 1 across the frame.
  double x0 = 1.0, x1 = -1.0, y0 = 1.0, y1 = -1.0;
  int sample = 0, inside = 0;
  double running = 0.0;
  for (const Object& o : scene.objects) {
    if (o.type != ObjectType::Triangles) continue;
    for (const auto& t : o.mesh.triangles) {
      const glm::dvec3 a(o.mesh.positions[t[0]]), b(o.mesh.positions[t[1]]),
          c(o.mesh.positions[t[2]]);
      running += 0.5 * glm::length(glm::cross(b - a, c - a));
      for (; sample < kViewSamples && (sample + 0.5) / kViewSamples * total < running; ++sample) {
        // The plastic number's 2-D sequence (R2), folded into the triangle.
        double u = std::fmod(0.5 + sample * 0.7548776662466927, 1.0);
        double v = std::fmod(0.5 + sample * 0.5698402909980532, 1.0);
        if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
        const glm::dvec3 d = a + u * (b - a) + v * (c - a) - eye;
        const double z = glm::dot(d, f);
        if (!(z >= double(camera.near) && z <= double(camera.far))) continue;
        const double sx = glm::dot(d, x) / (z * tan_x), sy = glm::dot(d, y) / (z * tan_y);
        if (!(std::fabs(sx) <= 1.0 && std::fabs(sy) <= 1.0)) continue;
        ++inside;
        x0 = std::min(x0, sx), x1 = std::max(x1, sx), y0 = std::min(y0, sy), y1 = std::max(y1, sy);
      }
    }
  }
  view.seen = float(inside) / float(kViewSamples);
  if (inside > 0) view.size = float(std::max(x1 - x0, y1 - y0) * 0.5);
  return view;
}

}  // namespace rvr
