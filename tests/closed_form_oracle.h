// The shading equation of docs/design.md and the pinhole camera, written out again in double
// precision for tests whose expected values must not come from the code under test
// (rvr/core/shading.h, rvr/core/camera.h, rvr/core/tessellate.h are not used here).
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "rvr/core/scene.h"

namespace rvr::oracle {

using glm::dvec3;

struct Ray {
  dvec3 origin;
  dvec3 direction;  // unit
};

// docs/design.md, "Space" and "Pixels": glm::lookAt's frame (eye-space -z is forward, +y up),
// vertical field of view, aspect width/height, y = 0 the top row, the sample of pixel (x, y) at
// (x + 0.5, y + 0.5) in pixel units from the top-left corner.
inline Ray camera_ray(const Camera& c, int width, int height, double px, double py) {
  dvec3 eye(c.eye), forward = glm::normalize(dvec3(c.target) - eye);
  dvec3 right = glm::normalize(glm::cross(forward, dvec3(c.up)));
  dvec3 up = glm::cross(right, forward);
  double tan_half = std::tan(double(c.fov_y_deg) * 3.14159265358979323846 / 360.0);
  double ndc_x = 2.0 * px / width - 1.0, ndc_y = 1.0 - 2.0 * py / height;
  dvec3 d = forward + right * (ndc_x * tan_half * double(width) / height) + up * (ndc_y * tan_half);
  return {eye, glm::normalize(d)};
}

// Nearest t > t_min where the ray meets the sphere's surface.
inline std::optional<double> hit_sphere(const Ray& r, const Sphere& s, double t_min = 1e-9) {
  dvec3 oc = r.origin - dvec3(s.center);
  double b = glm::dot(oc, r.direction), c = glm::dot(oc, oc) - double(s.radius) * s.radius;
  double disc = b * b - c;
  if (disc < 0) return std::nullopt;
  double root = std::sqrt(disc);
  for (double t : {-b - root, -b + root})
    if (t > t_min) return t;
  return std::nullopt;
}

// Where the ray meets the plane through `point` with normal `normal`, beyond t_min; nullopt
// when it runs parallel to it or meets it behind.
inline std::optional<double> hit_plane(const Ray& r, const dvec3& point, const dvec3& normal,
                                       double t_min) {
  double denom = glm::dot(normal, r.direction);
  if (std::abs(denom) < 1e-12) return std::nullopt;
  double t = glm::dot(point - r.origin, normal) / denom;
  if (!(t > t_min)) return std::nullopt;
  return t;
}

// The square of side 2 * half_size centred at point, facing normal, with its edges along the
// axes tessellate.h documents for it (world y, or x when the normal is near y, crossed with the
// normal). The tests keep pixels near its edges out, so only its interior matters.
inline std::optional<double> hit_square(const Ray& r, const Square& p, double t_min = 1e-9) {
  dvec3 n(p.normal);
  std::optional<double> t = hit_plane(r, dvec3(p.point), n, t_min);
  if (!t) return std::nullopt;
  dvec3 a = std::abs(n.y) < 0.9 ? dvec3(0, 1, 0) : dvec3(1, 0, 0);
  dvec3 u = glm::normalize(glm::cross(a, n)), v = glm::cross(n, u);
  dvec3 q = r.origin + *t * r.direction - dvec3(p.point);
  if (std::abs(glm::dot(q, u)) > p.half_size || std::abs(glm::dot(q, v)) > p.half_size)
    return std::nullopt;
  return t;
}

// The disc: the plane point within radius of its centre, in double precision.
inline std::optional<double> hit_disc(const Ray& r, const Disc& d, double t_min = 1e-9) {
  std::optional<double> t = hit_plane(r, dvec3(d.center), dvec3(d.normal), t_min);
  if (!t || glm::length(r.origin + *t * r.direction - dvec3(d.center)) > double(d.radius))
    return std::nullopt;
  return t;
}

struct PointLight {
  dvec3 position;
  dvec3 intensity;
};

// local = emission + ambient * diffuse
//       + sum_l visible_l * (diffuse * max(0, N.Ld) + specular * max(0, N.H)^shininess) * I_l /
//       d_l^2
// N faces the viewer; V = unit vector towards the eye.
inline dvec3 local_colour(const Material& m, const dvec3& ambient, const dvec3& P, const dvec3& N,
                          const dvec3& eye, const std::vector<PointLight>& lights,
                          const std::vector<double>& visible = {}) {
  dvec3 colour = dvec3(m.emission) + ambient * dvec3(m.diffuse);
  dvec3 V = glm::normalize(eye - P);
  for (size_t i = 0; i < lights.size(); ++i) {
    dvec3 to_light = lights[i].position - P;
    double d2 = glm::dot(to_light, to_light);
    dvec3 Ld = to_light / std::sqrt(d2);
    dvec3 H = glm::normalize(Ld + V);
    double n_dot_l = std::max(0.0, glm::dot(N, Ld)), n_dot_h = std::max(0.0, glm::dot(N, H));
    double spec =
        n_dot_h > 0 ? std::pow(n_dot_h, double(m.shininess)) : (m.shininess == 0.0f ? 1.0 : 0.0);
    double vis = visible.empty() ? 1.0 : visible[i];
    colour +=
        vis * (dvec3(m.diffuse) * n_dot_l + dvec3(m.specular) * spec) * lights[i].intensity / d2;
  }
  return colour;
}

// Solid angle of the rectangle [x0, x1] x [z0, z1] in the plane at height h > 0 above the
// origin, parallel to the xz plane: the integral of h / d^3 over it (each corner term is the
// solid angle of the rectangle between the foot point and that corner).
inline double rectangle_solid_angle(double x0, double x1, double z0, double z1, double h) {
  auto corner = [h](double x, double z) {
    return std::atan(x * z / (h * std::sqrt(x * x + z * z + h * h)));
  };
  return corner(x1, z1) - corner(x0, z1) - corner(x1, z0) + corner(x0, z0);
}

}  // namespace rvr::oracle
