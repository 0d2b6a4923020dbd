// The built-in scenes: small, deterministic, and chosen to stress one axis each
// (cornell: everything; spheres: analytic shapes; occluders: depth complexity; soup and
// tessphere: triangle count; effects: triangle count with shadows and a reflection to pay for).
#include <stddef.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/disc.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/square.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/tessellate.h"
#include "rvr/core/texture.h"
#include "rvr/scene_io/scene_loader.h"

namespace rvr {
namespace {

// The study sweeps soup and tessphere past 10^7 triangles, where the headline crossovers lie
// (at 10^8 a soup's scene alone is 4.8 GB; render's --max-triangles and --max-memory-mb guard
// what a single render may take).
constexpr size_t kMaxBuiltinCount = 100'000'000;

// splitmix64: a fixed generator, so soup:N is the same triangles on every platform.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  float uniform() { return float(next() >> 40) * (1.0f / 16777216.0f); }  // [0, 1)
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }

 private:
  uint64_t state_;
};

uint32_t add_material(Scene& s, const std::string& name, glm::vec3 diffuse,
                      glm::vec3 specular = glm::vec3(0.0f), float shininess = 32.0f,
                      glm::vec3 emission = glm::vec3(0.0f)) {
  Material m;
  m.name = name;
  m.diffuse = diffuse;
  m.specular = specular;
  m.shininess = shininess;
  m.emission = emission;
  s.materials.push_back(m);
  return uint32_t(s.materials.size() - 1);
}

Scene base_scene(const std::string& name) {
  Scene s;
  s.source = "builtin:" + name;
  s.materials.push_back(default_material());
  return s;
}

void look_at(Scene& s, glm::vec3 eye, glm::vec3 target, float fov, float near, float far) {
  s.camera.eye = eye;
  s.camera.target = target;
  s.camera.up = {0, 1, 0};
  s.camera.fov_y_deg = fov;
  s.camera.near = near;
  s.camera.far = far;
  s.camera.focus_distance = glm::length(target - eye);
}

void add_point_light(Scene& s, glm::vec3 position, glm::vec3 intensity) {
  Light l;
  l.type = LightType::Point;
  l.position = position;
  l.intensity = intensity;
  s.lights.push_back(l);
}

Object& add_object(Scene& s, const std::string& name, ObjectType type, uint32_t material) {
  Object o;
  o.name = name;
  o.type = type;
  o.material = material;
  s.objects.push_back(std::move(o));
  return s.objects.back();
}

// A quad v0 v1 v2 v3 (counter-clockwise seen from the front) as two flat triangles.
void add_quad(Scene& s, const std::string& name, uint32_t material, glm::vec3 v0, glm::vec3 v1,
              glm::vec3 v2, glm::vec3 v3) {
  Object& o = add_object(s, name, ObjectType::Triangles, material);
  o.mesh.positions = {v0, v1, v2, v3};
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
}

// A square floor facing +y, with its own diffuse material.
void add_floor(Scene& s, glm::vec3 colour, glm::vec3 centre, float half_size) {
  uint32_t m = add_material(s, "floor", colour);
  Object& o = add_object(s, "floor", ObjectType::Plane, m);
  o.plane = {centre, {0, 1, 0}, half_size};
}

void add_sphere(Scene& s, const std::string& name, uint32_t material, glm::vec3 c, float r) {
  Object& o = add_object(s, name, ObjectType::Sphere, material);
  o.sphere = {c, r};
}

// The Cornell box from its published geometry (Cornell University Program of Computer
// Graphics), scaled from millimetres to decimetres, with two spheres in place of the blocks.
// The published camera looks along +z, so +x is to the left: the red wall is on the left.
Scene cornell() {
  Scene s = base_scene("cornell");
  const float k = 0.01f;
  auto p = [k](float x, float y, float z) { return glm::vec3(x, y, z) * k; };
  uint32_t white = add_material(s, "white", {0.73f, 0.73f, 0.73f});
  uint32_t red = add_material(s, "red", {0.63f, 0.065f, 0.05f});
  uint32_t green = add_material(s, "green", {0.14f, 0.45f, 0.091f});
  // The lamp only emits: lit from its own light samples a few mm away it would blow up.
  uint32_t lamp =
      add_material(s, "lamp", {0.0f, 0.0f, 0.0f}, glm::vec3(0.0f), 32.0f, {4.0f, 4.0f, 4.0f});
  uint32_t mirror = add_material(s, "mirror", {0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}, 200.0f);
  s.materials[mirror].mirror = 0.85f;
  uint32_t glass = add_material(s, "glass", {0.05f, 0.05f, 0.05f}, {0.8f, 0.8f, 0.8f}, 300.0f);
  s.materials[glass].transparency = 0.9f;
  s.materials[glass].ior = 1.5f;

  add_quad(s, "floor", white, p(552.8f, 0, 0), p(0, 0, 0), p(0, 0, 559.2f), p(549.6f, 0, 559.2f));
  add_quad(s, "ceiling", white, p(556.0f, 548.8f, 0), p(556.0f, 548.8f, 559.2f),
           p(0, 548.8f, 559.2f), p(0, 548.8f, 0));
  add_quad(s, "back wall", white, p(549.6f, 0, 559.2f), p(0, 0, 559.2f), p(0, 548.8f, 559.2f),
           p(556.0f, 548.8f, 559.2f));
  add_quad(s, "green wall", green, p(0, 0, 559.2f), p(0, 0, 0), p(0, 548.8f, 0),
           p(0, 548.8f, 559.2f));
  add_quad(s, "red wall", red, p(552.8f, 0, 0), p(549.6f, 0, 559.2f), p(556.0f, 548.8f, 559.2f),
           p(556.0f, 548.8f, 0));
  // The lamp hangs 2 mm below the ceiling: coplanar with it, the two would tie in depth.
  add_quad(s, "lamp", lamp, p(343.0f, 548.6f, 227.0f), p(343.0f, 548.6f, 332.0f),
           p(213.0f, 548.6f, 332.0f), p(213.0f, 548.6f, 227.0f));
  add_sphere(s, "mirror ball", mirror, p(370.0f, 100.0f, 370.0f), 1.0f);
  add_sphere(s, "glass ball", glass, p(180.0f, 90.0f, 190.0f), 0.9f);

  s.image.width = 640;
  s.image.height = 480;
  look_at(s, p(278.0f, 273.0f, -800.0f), p(278.0f, 273.0f, 0.0f), 39.3077f, 1.0f, 100.0f);
  s.ambient = {0.03f, 0.03f, 0.03f};
  // The area light fills the lamp's opening, 5 cm below it, 4 x 4 samples.
  Light lamp_light;
  lamp_light.type = LightType::Area;
  lamp_light.corner = p(343.0f, 543.8f, 227.0f);
  lamp_light.edge_u = p(-130.0f, 0.0f, 0.0f);
  lamp_light.edge_v = p(0.0f, 0.0f, 105.0f);
  lamp_light.intensity = {14.0f, 14.0f, 14.0f};
  lamp_light.samples = 4;
  s.lights.push_back(lamp_light);
  return s;
}

// N small mirror balls (k x k cells, k = ceil(sqrt(N)), filled row by row from the back) on a
// floor between coloured walls: the tracer pays a reflection ray per mirror pixel whatever N
// is, a z-buffer a cube map (six views) per ball seen.
Scene mirror_balls(size_t n) {
  Scene s = base_scene("mirror_balls:" + std::to_string(n));
  add_floor(s, {0.6f, 0.6f, 0.55f}, {0, 0, 0}, 6.0f);
  uint32_t mirror = add_material(s, "mirror", {0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}, 200.0f);
  s.materials[mirror].mirror = 0.85f;
  const uint32_t red = add_material(s, "red", {0.7f, 0.1f, 0.1f});
  const uint32_t blue = add_material(s, "blue", {0.15f, 0.25f, 0.75f});
  const uint32_t teal = add_material(s, "teal", {0.2f, 0.5f, 0.5f});
  add_quad(s, "back wall", red, {-4.0f, 0.0f, -3.0f}, {4.0f, 0.0f, -3.0f}, {4.0f, 4.0f, -3.0f},
           {-4.0f, 4.0f, -3.0f});
  add_quad(s, "left wall", blue, {-4.0f, 0.0f, 5.0f}, {-4.0f, 0.0f, -3.0f}, {-4.0f, 4.0f, -3.0f},
           {-4.0f, 4.0f, 5.0f});
  add_quad(s, "backdrop", teal, {4.0f, 0.0f, 8.0f}, {-4.0f, 0.0f, 8.0f}, {-4.0f, 4.0f, 8.0f},
           {4.0f, 4.0f, 8.0f});
  const size_t k = size_t(std::ceil(std::sqrt(double(n))));
  // The balls fill x in [-2.5, 2.5], z in [-2, 2], each a third of its cell across.
  const float cell = 5.0f / float(k), depth = 4.0f / float(k);
  const float r = 0.3f * std::min(cell, depth);
  for (size_t i = 0; i < n; ++i) {
    const size_t row = i / k, column = i % k;
    const glm::vec3 centre(-2.5f + (float(column) + 0.5f) * cell, r,
                           -2.0f + (float(row) + 0.5f) * depth);
    add_sphere(s, "ball " + std::to_string(i), mirror, centre, r);
  }
  look_at(s, {0.5f, 3.0f, 6.0f}, {0.0f, 0.3f, 0.0f}, 50.0f, 0.1f, 100.0f);
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_point_light(s, {2.0f, 5.0f, 4.0f}, {40.0f, 40.0f, 40.0f});
  return s;
}

Scene spheres() {
  Scene s = base_scene("spheres");
  add_floor(s, {0.6f, 0.6f, 0.55f}, {0, 0, 0}, 8.0f);
  const int n = 5;
  const int centre = n / 2;  // the grid's middle row and column stand at the origin
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      float hue = float(i * n + j) / float(n * n);
      glm::vec3 colour(0.2f + 0.7f * hue, 0.3f + 0.5f * (1.0f - hue), 0.9f - 0.6f * hue);
      uint32_t m = add_material(s, "ball" + std::to_string(i * n + j), colour, glm::vec3(0.4f),
                                16.0f + 8.0f * float(i));
      add_sphere(s, "sphere " + std::to_string(i) + "," + std::to_string(j), m,
                 {float(i - centre) * 1.1f, 0.45f, float(j - centre) * 1.1f}, 0.45f);
    }
  }
  look_at(s, {0.0f, 4.0f, 7.5f}, {0.0f, 0.3f, 0.0f}, 45.0f, 0.1f, 100.0f);
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_point_light(s, {-3.0f, 6.0f, 4.0f}, {40.0f, 40.0f, 40.0f});
  add_point_light(s, {4.0f, 3.0f, 2.0f}, {10.0f, 9.0f, 8.0f});
  return s;
}

void add_disc(Scene& s, const std::string& name, uint32_t material, glm::vec3 c, glm::vec3 n,
              float r) {
  Object& o = add_object(s, name, ObjectType::Disc, material);
  o.disc = {c, glm::normalize(n), r};
}

// Discs in every orientation on a floor: a table top with a plate above it, a wheel facing the
// camera, one tilted towards the light, and a round mirror behind them (full mode reflects the
// others in it).
Scene discs() {
  Scene s = base_scene("discs");
  add_floor(s, {0.6f, 0.6f, 0.55f}, {0, 0, 0}, 6.0f);
  uint32_t wood = add_material(s, "wood", {0.55f, 0.35f, 0.2f}, glm::vec3(0.2f), 12.0f);
  uint32_t china = add_material(s, "china", {0.85f, 0.85f, 0.8f}, glm::vec3(0.6f), 64.0f);
  uint32_t red = add_material(s, "red", {0.7f, 0.1f, 0.1f}, glm::vec3(0.3f), 24.0f);
  uint32_t blue = add_material(s, "blue", {0.15f, 0.25f, 0.75f}, glm::vec3(0.3f), 24.0f);
  uint32_t mirror = add_material(s, "mirror", {0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}, 200.0f);
  s.materials[mirror].mirror = 0.85f;
  add_disc(s, "table", wood, {0.0f, 0.8f, 0.0f}, {0, 1, 0}, 1.2f);
  add_disc(s, "plate", china, {0.3f, 0.95f, 0.2f}, {0, 1, 0}, 0.35f);
  add_disc(s, "wheel", red, {-2.0f, 1.0f, -0.5f}, {0, 0, 1}, 0.9f);
  add_disc(s, "tilted", blue, {2.0f, 0.9f, -0.3f}, {-1, 1, 1}, 0.8f);
  add_disc(s, "round mirror", mirror, {0.0f, 1.7f, -2.8f}, {0, 0, 1}, 1.4f);
  look_at(s, {0.0f, 3.2f, 6.5f}, {0.0f, 0.8f, 0.0f}, 45.0f, 0.1f, 100.0f);
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_point_light(s, {-3.0f, 6.0f, 4.0f}, {40.0f, 40.0f, 40.0f});
  add_point_light(s, {4.0f, 3.0f, 2.0f}, {10.0f, 9.0f, 8.0f});
  return s;
}

// A wall of N flat square mirrors (k x k cells, k = ceil(sqrt(N)), filled row by row from the
// top), each turned a few degrees its own way, facing three balls on a floor: the tracer pays a
// reflection ray per mirror pixel whatever N is, a z-buffer a whole view per mirror seen. N = 1
// is one large mirror filling the wall.
Scene mirrors(size_t n) {
  Scene s = base_scene("mirrors:" + std::to_string(n));
  add_floor(s, {0.6f, 0.6f, 0.55f}, {0, 0, 0}, 6.0f);
  uint32_t mirror = add_material(s, "mirror", {0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}, 200.0f);
  s.materials[mirror].mirror = 0.85f;
  const uint32_t red = add_material(s, "red", {0.7f, 0.1f, 0.1f}, glm::vec3(0.3f), 24.0f);
  const uint32_t blue = add_material(s, "blue", {0.15f, 0.25f, 0.75f}, glm::vec3(0.3f), 24.0f);
  const uint32_t gold = add_material(s, "gold", {0.75f, 0.6f, 0.2f}, glm::vec3(0.5f), 48.0f);
  const uint32_t teal = add_material(s, "teal", {0.2f, 0.5f, 0.5f});
  // Behind the camera, for the mirrors to show.
  add_quad(s, "backdrop", teal, {6.0f, 0.0f, 8.0f}, {-6.0f, 0.0f, 8.0f}, {-6.0f, 6.0f, 8.0f},
           {6.0f, 6.0f, 8.0f});
  const size_t k = size_t(std::ceil(std::sqrt(double(n))));
  // The wall: x in [-2.4, 2.4], y in [0.2, 3.8], at z = -2.
  const float cell_w = 4.8f / float(k), cell_h = 3.6f / float(k);
  for (size_t i = 0; i < n; ++i) {
    const size_t row = i / k, column = i % k;
    const glm::vec3 centre(-2.4f + (float(column) + 0.5f) * cell_w,
                           3.8f - (float(row) + 0.5f) * cell_h, -2.0f);
    // Each tile turned its own way (none when it is the only one), so each has its own plane.
    const float yaw = n == 1 ? 0.0f : glm::radians(8.0f) * std::sin(1.7f * float(i) + 0.3f);
    const float pitch = n == 1 ? 0.0f : glm::radians(6.0f) * std::cos(2.3f * float(i) + 1.1f);
    const glm::vec3 normal = glm::normalize(glm::vec3(
        std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch)));
    const glm::vec3 u = glm::normalize(glm::cross(glm::vec3(0, 1, 0), normal));
    const glm::vec3 v = glm::cross(normal, u);
    const float hu = 0.46f * cell_w, hv = 0.46f * cell_h;
    add_quad(s, "mirror " + std::to_string(i), mirror, centre - hu * u - hv * v,
             centre + hu * u - hv * v, centre + hu * u + hv * v, centre - hu * u + hv * v);
  }
  add_sphere(s, "red ball", red, {-1.0f, 0.6f, 0.2f}, 0.6f);
  add_sphere(s, "blue ball", blue, {0.9f, 0.5f, 0.8f}, 0.5f);
  add_sphere(s, "gold ball", gold, {0.1f, 0.4f, 2.2f}, 0.4f);
  look_at(s, {0.8f, 2.0f, 6.0f}, {0.0f, 1.4f, -1.0f}, 50.0f, 0.1f, 100.0f);
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_point_light(s, {2.0f, 5.0f, 4.0f}, {40.0f, 40.0f, 40.0f});
  return s;
}

// N parallel quads facing the camera, one behind another; the rear ones are hidden by the
// front one wherever it covers them, so the z-buffer shades N fragments there and the tracer 1.
// back_to_front submits the rearmost first: the order hi-z cannot exploit.
Scene occluders(size_t n, bool back_to_front = false) {
  Scene s = base_scene((back_to_front ? "occluders_back:" : "occluders:") + std::to_string(n));
  const float spacing = 0.05f;
  for (size_t i = 0; i < n; ++i) {
    float t = n > 1 ? float(i) / float(n - 1) : 0.0f;
    uint32_t m =
        add_material(s, "quad" + std::to_string(i), {0.9f - 0.6f * t, 0.3f, 0.2f + 0.7f * t});
    Object& o = add_object(s, "quad " + std::to_string(i), ObjectType::Plane, m);
    o.plane = {{0.0f, 0.0f, -float(i) * spacing}, {0, 0, 1}, 1.0f};
  }
  if (back_to_front) std::reverse(s.objects.begin(), s.objects.end());
  look_at(s, {0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 45.0f, 0.1f, 100.0f);
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_point_light(s, {1.0f, 1.5f, 3.0f}, {10.0f, 10.0f, 10.0f});
  return s;
}

// N random triangles in a box. Triangle size shrinks as 1/sqrt(N), so the projected area (and
// so the depth complexity) stays about the same as N grows: only the triangle count varies.
Scene soup(size_t n) {
  Scene s = base_scene("soup:" + std::to_string(n));
  uint32_t m = add_material(s, "soup", {0.7f, 0.6f, 0.4f}, {0.3f, 0.3f, 0.3f}, 24.0f);
  Object& o = add_object(s, "soup", ObjectType::Triangles, m);
  SplitMix64 rng(0x5EEDull + n);
  float size = std::min(0.5f, 0.25f * std::sqrt(1000.0f / float(n)));
  o.mesh.positions.reserve(3 * n);
  o.mesh.triangles.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 c(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    uint32_t base = uint32_t(o.mesh.positions.size());
    for (int k = 0; k < 3; ++k) {
      o.mesh.positions.push_back(
          c + size * glm::vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
    }
    o.mesh.triangles.push_back({base, base + 1, base + 2});
  }
  look_at(s, {0.0f, 0.0f, 3.5f}, {0.0f, 0.0f, 0.0f}, 45.0f, 0.1f, 100.0f);
  s.ambient = {0.08f, 0.08f, 0.08f};
  add_point_light(s, {2.0f, 3.0f, 4.0f}, {25.0f, 25.0f, 25.0f});
  return s;
}

// One smooth sphere of about N triangles, as a mesh: primitive ids are triangle indices.
Scene tessphere(size_t n) {
  Scene s = base_scene("tessphere:" + std::to_string(n));
  uint32_t m = add_material(s, "sphere", {0.3f, 0.5f, 0.8f}, {0.5f, 0.5f, 0.5f}, 48.0f);
  Object& o = add_object(s, "sphere", ObjectType::Triangles, m);
  o.mesh = tessellate_sphere({{0, 0, 0}, 1.0f}, sphere_segments_for_triangles(n));
  look_at(s, {0.0f, 0.6f, 3.2f}, {0.0f, 0.0f, 0.0f}, 45.0f, 0.1f, 100.0f);
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_point_light(s, {2.0f, 3.0f, 3.0f}, {20.0f, 20.0f, 20.0f});
  return s;
}

// tessphere's sphere on a floor in front of a mirror, lit from above: in full mode the sphere's
// shadow falls on the floor (shadow rays or shadow maps over its N triangles) and the mirror
// shows it again (reflection rays traced into its N triangles; the z-buffers draw its N
// triangles again into the mirror's reflected view).
Scene effects(size_t n) {
  Scene s = base_scene("effects:" + std::to_string(n));
  uint32_t m = add_material(s, "sphere", {0.3f, 0.5f, 0.8f}, {0.5f, 0.5f, 0.5f}, 48.0f);
  Object& o = add_object(s, "sphere", ObjectType::Triangles, m);
  o.mesh = tessellate_sphere({{0.5f, 0.0f, 0.0f}, 1.0f}, sphere_segments_for_triangles(n));
  add_floor(s, {0.7f, 0.7f, 0.65f}, {0.0f, -1.0f, 0.0f}, 5.0f);
  uint32_t mirror = add_material(s, "mirror", {0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}, 200.0f);
  s.materials[mirror].mirror = 0.85f;
  // Turned towards the sphere and the camera, to its left: the reflection is seen beside it.
  Object& wall = add_object(s, "mirror", ObjectType::Plane, mirror);
  wall.plane = {{-1.6f, 0.8f, -1.6f}, glm::normalize(glm::vec3(0.7f, 0.0f, 0.5f)), 1.8f};
  look_at(s, {1.2f, 1.4f, 5.5f}, {-0.2f, 0.2f, -0.4f}, 45.0f, 0.1f, 100.0f);
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_point_light(s, {3.0f, 4.0f, 2.5f}, {30.0f, 30.0f, 30.0f});
  return s;
}

std::shared_ptr<CsgNode> csg_sphere(glm::vec3 c, float r) {
  auto n = std::make_shared<CsgNode>();
  n->sphere = {c, r};
  return n;
}

std::shared_ptr<CsgNode> csg_op(CsgOp op, std::shared_ptr<const CsgNode> a,
                                std::shared_ptr<const CsgNode> b) {
  auto n = std::make_shared<CsgNode>();
  n->is_leaf = false;
  n->op = op;
  n->a = std::move(a);
  n->b = std::move(b);
  return n;
}

void add_csg(Scene& s, const std::string& name, uint32_t material,
             std::shared_ptr<const CsgNode> tree) {
  add_object(s, name, ObjectType::Csg, material).csg = std::move(tree);
}

// A closed box (outward, counter-clockwise faces) centred at c with half extents h.
void add_box(Scene& s, const std::string& name, uint32_t material, glm::vec3 c, glm::vec3 h) {
  Object& o = add_object(s, name, ObjectType::Triangles, material);
  for (int i = 0; i < 8; ++i)
    o.mesh.positions.push_back(
        c + glm::vec3(i & 1 ? h.x : -h.x, i & 2 ? h.y : -h.y, i & 4 ? h.z : -h.z));
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 4, 6, 2},
                                {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}};
  for (const auto& q : quads) {
    o.mesh.triangles.push_back({q[0], q[1], q[2]});
    o.mesh.triangles.push_back({q[0], q[2], q[3]});
  }
}

// Every CSG operation on spheres, and a nested tree, on a floor.
Scene csg() {
  Scene s = base_scene("csg");
  add_floor(s, {0.6f, 0.6f, 0.6f}, {0, 0, 0}, 6.0f);
  uint32_t red = add_material(s, "red", {0.8f, 0.2f, 0.15f}, glm::vec3(0.3f), 32.0f);
  uint32_t green = add_material(s, "green", {0.2f, 0.7f, 0.25f}, glm::vec3(0.3f), 32.0f);
  uint32_t blue = add_material(s, "blue", {0.2f, 0.3f, 0.85f}, glm::vec3(0.3f), 32.0f);
  uint32_t gold = add_material(s, "gold", {0.85f, 0.65f, 0.2f}, glm::vec3(0.4f), 64.0f);
  add_csg(s, "union", red,
          csg_op(CsgOp::Union, csg_sphere({-2.4f, 0.6f, 0}, 0.6f),
                 csg_sphere({-2.0f, 0.9f, 0.2f}, 0.5f)));
  add_csg(s, "intersection", green,
          csg_op(CsgOp::Intersection, csg_sphere({-0.55f, 0.7f, 0}, 0.7f),
                 csg_sphere({-0.05f, 0.7f, 0}, 0.7f)));
  add_csg(s, "difference", blue,
          csg_op(CsgOp::Difference, csg_sphere({1.0f, 0.7f, 0}, 0.7f),
                 csg_sphere({1.3f, 1.0f, 0.5f}, 0.5f)));
  // (A u B) - (C n D): a dumbbell with a lens-shaped bite.
  auto dumbbell = csg_op(CsgOp::Union, csg_sphere({2.5f, 0.5f, -0.3f}, 0.5f),
                         csg_sphere({2.9f, 0.5f, 0.4f}, 0.5f));
  auto lens = csg_op(CsgOp::Intersection, csg_sphere({2.5f, 0.9f, 0.5f}, 0.5f),
                     csg_sphere({2.9f, 0.9f, 0.3f}, 0.5f));
  add_csg(s, "nested", gold, csg_op(CsgOp::Difference, dumbbell, lens));
  look_at(s, {0.0f, 3.0f, 6.0f}, {0.2f, 0.5f, 0.0f}, 45.0f, 0.1f, 100.0f);
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_point_light(s, {-2.0f, 5.0f, 4.0f}, {40.0f, 40.0f, 40.0f});
  return s;
}

// Spheres at several depths, the middle row in focus.
Scene dof() {
  Scene s = base_scene("dof");
  add_floor(s, {0.5f, 0.5f, 0.5f}, {0, 0, -4}, 10.0f);
  for (int i = 0; i < 7; ++i) {
    float t = float(i) / 6.0f;
    uint32_t m = add_material(s, "ball" + std::to_string(i),
                              {0.9f - 0.7f * t, 0.4f, 0.2f + 0.7f * t}, glm::vec3(0.5f), 64.0f);
    add_sphere(s, "sphere " + std::to_string(i), m,
               {-2.4f + 0.8f * float(i), 0.35f, 1.5f - 1.5f * float(i)}, 0.35f);
  }
  look_at(s, {0.0f, 1.2f, 4.0f}, {0.0f, 0.35f, -3.0f}, 40.0f, 0.1f, 100.0f);
  s.camera.aperture_radius = 0.12f;
  s.camera.focus_distance = glm::length(glm::vec3(-0.0f, 0.35f, -3.0f) - s.camera.eye);
  s.image.samples_per_pixel = 16;
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_point_light(s, {2.0f, 5.0f, 3.0f}, {40.0f, 40.0f, 40.0f});
  return s;
}

// A glass slab and a glass sphere in front of coloured quads: refraction bends their edges.
// Between them and behind, a tinted pane of ior 1: its transmitted rays go straight on (the
// over operator), so what it shows is the scene behind it, tinted.
Scene glass() {
  Scene s = base_scene("glass");
  add_floor(s, {0.6f, 0.6f, 0.6f}, {0, 0, 0}, 6.0f);
  const glm::vec3 colours[4] = {
      {0.85f, 0.2f, 0.2f}, {0.2f, 0.75f, 0.25f}, {0.2f, 0.3f, 0.9f}, {0.9f, 0.8f, 0.2f}};
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 2; ++j) {
      uint32_t m =
          add_material(s, "quad" + std::to_string(i) + std::to_string(j), colours[(i + j) % 4]);
      float x0 = -2.0f + float(i), y0 = float(j);
      add_quad(s, "wall " + std::to_string(i) + "," + std::to_string(j), m, {x0, y0, -1.5f},
               {x0 + 1, y0, -1.5f}, {x0 + 1, y0 + 1, -1.5f}, {x0, y0 + 1, -1.5f});
    }
  }
  Material glass_material;
  glass_material.name = "glass";
  glass_material.diffuse = glm::vec3(0.0f);
  glass_material.specular = glm::vec3(0.8f);
  glass_material.shininess = 200.0f;
  glass_material.transparency = 0.95f;
  glass_material.ior = 1.5f;
  s.materials.push_back(glass_material);
  uint32_t g = uint32_t(s.materials.size() - 1);
  add_box(s, "slab", g, {-0.9f, 0.8f, 0.0f}, {0.6f, 0.7f, 0.15f});
  add_sphere(s, "glass ball", g, {0.9f, 0.6f, 0.2f}, 0.6f);
  const uint32_t tint = add_material(s, "tinted pane", {0.3f, 0.55f, 0.8f});
  s.materials[tint].transparency = 0.6f;
  s.materials[tint].ior = 1.0f;
  add_quad(s, "pane", tint, {-0.25f, 0.2f, -0.6f}, {0.25f, 0.2f, -0.6f}, {0.25f, 1.9f, -0.6f},
           {-0.25f, 1.9f, -0.6f});
  look_at(s, {0.0f, 1.1f, 4.5f}, {0.0f, 0.8f, 0.0f}, 40.0f, 0.1f, 100.0f);
  s.ambient = {0.08f, 0.08f, 0.08f};
  add_point_light(s, {1.5f, 4.0f, 4.0f}, {30.0f, 30.0f, 30.0f});
  return s;
}

// A checkerboard texture of squares x squares squares, each `texels` texels wide, in two
// colours (linear RGB), built in memory.
Texture checkerboard(int squares, int texels, glm::vec3 a, glm::vec3 b) {
  TextureLevel level;
  level.width = level.height = squares * texels;
  level.texels.resize(size_t(level.width) * size_t(level.height));
  for (int y = 0; y < level.height; ++y)
    for (int x = 0; x < level.width; ++x)
      level.texels[size_t(y) * size_t(level.width) + size_t(x)] =
          ((x / texels + y / texels) % 2 == 0) ? a : b;
  Texture t;
  t.file = "checkerboard";
  t.mips = std::make_shared<const MipChain>(build_mip_chain(std::move(level)));
  return t;
}

// A checkerboard-textured floor seen at grazing angles (the texture repeats 32 times across
// it: every mip level shows, up to the horizon) and a triangle whose corners are red, green
// and blue (vertex colours), standing on it.
Scene textured() {
  Scene s = base_scene("textured");
  s.textures.push_back(checkerboard(8, 16, {0.9f, 0.9f, 0.85f}, {0.1f, 0.15f, 0.4f}));
  uint32_t floor = add_material(s, "checker", glm::vec3(1.0f));
  s.materials[floor].texture = 0;
  uint32_t white = add_material(s, "vertex colours", glm::vec3(1.0f));
  const float h = 40.0f, repeats = 32.0f;
  Object& f = add_object(s, "floor", ObjectType::Triangles, floor);
  f.mesh.positions = {{-h, 0, h}, {h, 0, h}, {h, 0, -h}, {-h, 0, -h}};
  f.mesh.uvs = {{0, 0}, {repeats, 0}, {repeats, repeats}, {0, repeats}};
  f.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  Object& t = add_object(s, "triangle", ObjectType::Triangles, white);
  t.mesh.positions = {{-1.2f, 0.0f, -1.0f}, {1.2f, 0.0f, -1.0f}, {0.0f, 1.8f, -1.0f}};
  t.mesh.colours = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  t.mesh.triangles = {{0, 1, 2}};
  look_at(s, {0.0f, 1.0f, 5.0f}, {0.0f, 0.6f, -2.0f}, 45.0f, 0.05f, 200.0f);
  s.ambient = {0.1f, 0.1f, 0.1f};
  add_point_light(s, {2.0f, 6.0f, 4.0f}, {60.0f, 60.0f, 60.0f});
  return s;
}

}  // namespace

std::vector<BuiltinSceneInfo> builtin_scenes() {
  return {
      {"cornell",
       "the Cornell box (published geometry), a mirror and a glass sphere, an area light"},
      {"spheres", "a 5x5 grid of analytic spheres on a square plane, two point lights"},
      {"occluders:N",
       "N parallel quads one behind another facing the camera, drawn front to back: depth "
       "complexity N (default 8)"},
      {"occluders_back:N", "the same quads drawn back to front (what hierarchical z cannot skip)"},
      {"soup:N", "N random triangles in a box, seeded, constant total area (default 1000)"},
      {"tessphere:N", "one smooth sphere tessellated into about N triangles (default 10000)"},
      {"effects:N",
       "tessphere's sphere of about N triangles on a floor in front of a mirror: a shadow and a "
       "reflection of N triangles (default 10000)"},
      {"csg", "union, intersection, difference of spheres and a nested tree, on a floor"},
      {"discs", "discs in every orientation on a floor, one of them a round mirror"},
      {"mirrors:N",
       "a wall of N flat square mirrors, each turned its own way, facing three balls (default "
       "16; 1: one large mirror)"},
      {"mirror_balls:N",
       "N small mirror balls on a floor between coloured walls (default 16): a z-buffer draws a "
       "cube map per ball"},
      {"dof", "spheres at several depths, thin lens focused on the middle one, 16 samples"},
      {"glass",
       "a glass slab, a glass sphere and a tinted pane (ior 1) in front of coloured quads"},
      {"textured",
       "a checkerboard-textured floor to the horizon (every mip level) and a vertex-coloured "
       "triangle"},
  };
}

Expected<Scene> make_builtin_scene(const std::string& spec) {
  std::string name = spec;
  size_t count = 0;
  bool has_count = false;
  if (size_t colon = spec.find(':'); colon != std::string::npos) {
    name = spec.substr(0, colon);
    std::string digits = spec.substr(colon + 1);
    auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), count);
    if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() || count < 1 ||
        count > kMaxBuiltinCount) {
      return bad_input("builtin:" + spec + ": N must be an integer in 1.." +
                       std::to_string(kMaxBuiltinCount) + ", got '" + digits + "'");
    }
    has_count = true;
  }
  auto no_count = [&]() -> Expected<Scene> {
    return bad_input("builtin:" + spec + ": scene '" + name + "' takes no ':N'");
  };
  if (name == "cornell") return has_count ? no_count() : Expected<Scene>(cornell());
  if (name == "spheres") return has_count ? no_count() : Expected<Scene>(spheres());
  if (name == "occluders") return occluders(has_count ? count : 8);
  if (name == "occluders_back") return occluders(has_count ? count : 8, true);
  if (name == "soup") return soup(has_count ? count : 1000);
  if (name == "tessphere") return tessphere(has_count ? count : 10000);
  if (name == "effects") return effects(has_count ? count : 10000);
  if (name == "csg") return has_count ? no_count() : Expected<Scene>(csg());
  if (name == "discs") return has_count ? no_count() : Expected<Scene>(discs());
  if (name == "mirrors") {
    // Each mirror seen costs a z-buffer a whole view: past a few thousand, a frame takes hours.
    constexpr size_t kMaxMirrors = 4096;
    if (count > kMaxMirrors)
      return bad_input("builtin:" + spec + ": at most " + std::to_string(kMaxMirrors) +
                       " mirrors, got " + std::to_string(count));
    return mirrors(has_count ? count : 16);
  }
  if (name == "mirror_balls") {
    // Each ball seen costs a z-buffer six views.
    constexpr size_t kMaxBalls = 1024;
    if (count > kMaxBalls)
      return bad_input("builtin:" + spec + ": at most " + std::to_string(kMaxBalls) +
                       " balls, got " + std::to_string(count));
    return mirror_balls(has_count ? count : 16);
  }
  if (name == "dof") return has_count ? no_count() : Expected<Scene>(dof());
  if (name == "glass") return has_count ? no_count() : Expected<Scene>(glass());
  if (name == "textured") return has_count ? no_count() : Expected<Scene>(textured());
  return bad_input("builtin:" + spec + ": no such built-in scene (see 'rvr scenes')");
}

}  // namespace rvr
