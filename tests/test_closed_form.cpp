// Closed-form oracles: every renderer of the table (every entry and variant, GL included)
// renders one analytic sphere over a square plane, and every pixel away from an edge must
// equal the shading equation of docs/design.md evaluated here, in double precision, from a
// camera ray and a ray-sphere / ray-plane intersection the test computes itself
// (closed_form_oracle.h). Nothing of rvr/core/shading.h, camera.h or tessellate.h is used for
// the expected values, so a wrong term shared by the C++ and the GLSL fails here even though
// every renderer agrees with every other.
#include <gtest/gtest.h>
#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "closed_form_oracle.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/disc.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/square.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/tessellate.h"
#include "rvr/renderers/registry.h"

namespace rvr {
namespace {

using glm::dvec3;
using oracle::PointLight;

constexpr int kSegments = 64;  // z-buffers' sphere tessellation: 64 longitudes, 32 rings
const double kPi = 3.14159265358979323846;

// Plane pixels (and analytic spheres): 1e-4 absolute on colours of order 1. Every renderer
// shades in float: positions and normals carry relative errors of ~1e-6 (interpolation or
// intersection), which move the colour by ~1e-6 times the largest derivative of the equation,
// shininess 64 included (64 * 1e-6 * specular * I / d^2 < 1e-4).
constexpr double kTolerance = 1e-4;

// Pixels whose samples at +-1.5 px in x and y do not all see the same surface (and, where it
// matters, the same shadow side and the same reflected object) are not checked. At a silhouette
// or a shadow edge the pixel centre may fall on either side: float rounding of the edge, the
// rasterizer's top-left rule, and a tessellated outline inside the analytic circle (here by at
// most the sagitta r * (1 - cos(2 pi / 64)) ~ 0.0013, 0.1 px). 1.5 px keeps every checked
// pixel's footprint and its neighbours on one side of every edge.
constexpr double kEdgeMarginPx = 1.5;

std::vector<PointLight> point_lights(const Scene& s) {
  std::vector<PointLight> lights;
  for (const Light& l : s.lights) lights.push_back({dvec3(l.position), dvec3(l.intensity)});
  return lights;
}

// What the test knows about one image position from geometry alone.
struct SurfacePoint {
  int object = -1;  // index in scene.objects, -1 for the background
  oracle::Ray ray;
  dvec3 P, N;  // N faces the viewer
};

// Where the ray meets object o first, and the surface's normal there (not yet facing the viewer).
std::optional<double> hit(const oracle::Ray& ray, const Object& o) {
  switch (o.type) {
    case ObjectType::Sphere:
      return oracle::hit_sphere(ray, o.sphere);
    case ObjectType::Plane:
      return oracle::hit_square(ray, o.plane);
    case ObjectType::Disc:
      return oracle::hit_disc(ray, o.disc);
    case ObjectType::Triangles:
    case ObjectType::Csg:
      break;
  }
  ADD_FAILURE() << "the oracle traces spheres, squares and discs only";
  return std::nullopt;
}
dvec3 normal_at(const Object& o, const dvec3& P) {
  if (o.type == ObjectType::Sphere) return glm::normalize(P - dvec3(o.sphere.center));
  return dvec3(o.type == ObjectType::Disc ? o.disc.normal : o.plane.normal);
}

SurfacePoint trace(const Scene& s, double px, double py) {
  SurfacePoint sp;
  sp.ray = oracle::camera_ray(s.camera, s.image.width, s.image.height, px, py);
  double nearest = 1e300;
  for (size_t i = 0; i < s.objects.size(); ++i) {
    const Object& o = s.objects[i];
    std::optional<double> t = hit(sp.ray, o);
    if (!t || *t >= nearest) continue;
    nearest = *t;
    sp.object = int(i);
    sp.P = sp.ray.origin + *t * sp.ray.direction;
    sp.N = normal_at(o, sp.P);
  }
  if (sp.object >= 0 && glm::dot(sp.N, sp.ray.direction) > 0) sp.N = -sp.N;
  return sp;
}

// Sphere between P and the light: 1 lit, 0 shadowed, -1 too close to the shadow's edge to
// say. The margin (world units, measured at the occluder): the tessellated occluder lies inside
// the analytic one by at most the sagitta 0.5 * (1 - cos(2 pi / 64)) = 0.0024; a shadow map of
// 1024 texels over a 90-degree face has texels of at most 2/1024 rad, 0.004 at the ~2 units
// between light and sphere, and a boundary may move by a texel either way. 0.02 is 2.5 times
// their sum.
constexpr double kShadowMargin = 0.02;
int lit_by(const dvec3& P, const dvec3& L, const Sphere& occluder) {
  dvec3 c(occluder.center), d = L - P;
  double s = std::clamp(glm::dot(c - P, d) / glm::dot(d, d), 0.0, 1.0);
  double dist = glm::length(c - (P + s * d));
  if (dist < occluder.radius - kShadowMargin) return 0;
  if (dist > occluder.radius + kShadowMargin) return 1;
  return -1;
}

struct RenderedFrame {
  FrameBuffers buffers;
  std::vector<std::string> warnings;
};

// A table entry or variant with its own settings over ours; raster pinned to OSMesa unless the
// variant asks for EGL, as in test_conformance.
RenderedFrame render(const RendererChoice& choice, const Scene& scene, RenderMode mode) {
  RendererConfig config{GlBackend::OsMesa};
  RenderOptions options;
  options.mode = mode;
  options.spheres = SphereMode::Analytic;
  options.sphere_segments = kSegments;
  choice.apply(config, options);
  auto renderer = choice.info->create(config);
  EXPECT_TRUE(renderer.ok()) << (renderer.ok() ? "" : renderer.error().message);
  if (!renderer.ok()) return {};
  Expected<RenderOutput> out = renderer.value()->render(scene, options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  if (!out.ok()) return {};
  return {std::move(out->buffers), out->warnings};
}

// The z-buffers draw spheres as the 64-segment UV sphere; the tracers and hybrids (whose hits
// are the tracer's) intersect the analytic sphere.
bool draws_sphere_meshes(const RendererChoice& c) {
  return c.info->order == LoopOrder::TriangleMajor;
}

// How far the colour of a tessellated sphere may be from the analytic one at a pixel.
// Derivation. Every vertex of the UV sphere lies on the sphere and its normal is radial, so at
// a point Q of a triangle the interpolated normal (v_i - c barycentrically mixed, normalised)
// is exactly normalize(Q - c): the error is only that the pixel's ray meets the triangle at Q
// rather than the sphere at P. A triangle spans at most D = 2 pi / 64 in latitude and
// longitude, so its points lie within the sagitta h = r (1 - cos D) under the sphere. Along a
// ray meeting the surface at incidence i (cos i = N.V), |Q - P| <= h / cos i, and the angle
// between the radial directions of Q and P is at most (h / (r - h)) tan i. The tolerance is the
// largest change of the formula when P moves by up to that distance along the ray and N tilts
// by up to that angle in any direction (sampled at half and full size, 8 directions), plus
// kTolerance. Beyond cos i < 0.3 (the last ~2 px of the disc) the bound grows without limit,
// so those pixels are skipped.
struct TessellationBound {
  double eps_position, eps_normal;
};
std::optional<TessellationBound> tessellation_bound(const SurfacePoint& sp, double radius) {
  double cos_i = glm::dot(sp.N, -sp.ray.direction);
  if (cos_i < 0.3) return std::nullopt;
  double h_over_r = 1.0 - std::cos(2.0 * kPi / kSegments);
  double tan_i = std::sqrt(1.0 - cos_i * cos_i) / cos_i;
  return TessellationBound{radius * h_over_r / cos_i, h_over_r / (1.0 - h_over_r) * tan_i};
}

double tessellation_tolerance(const SurfacePoint& sp, const TessellationBound& b,
                              const std::function<dvec3(const dvec3&, const dvec3&)>& colour) {
  dvec3 exact = colour(sp.P, sp.N);
  dvec3 a = std::abs(sp.N.y) < 0.9 ? dvec3(0, 1, 0) : dvec3(1, 0, 0);
  dvec3 u = glm::normalize(glm::cross(a, sp.N)), v = glm::cross(sp.N, u);
  double worst = 0;
  for (double move : {-1.0, 0.0, 1.0}) {
    dvec3 P = sp.P + move * b.eps_position * sp.ray.direction;
    for (double size : {0.0, 0.5, 1.0}) {
      for (int k = 0; k < 8; ++k) {
        double phi = 2 * kPi * k / 8, tilt = size * b.eps_normal;
        dvec3 N = glm::normalize(sp.N * std::cos(tilt) +
                                 (u * std::cos(phi) + v * std::sin(phi)) * std::sin(tilt));
        dvec3 diff = glm::abs(colour(P, N) - exact);
        worst = std::max({worst, diff.x, diff.y, diff.z});
      }
    }
  }
  return worst + kTolerance;
}

// The comparison of one frame with the formula, pixel by pixel.
struct Check {
  size_t checked_plane = 0, checked_object = 0, failed = 0;
  double worst_excess = 0;
  std::string worst;

  void pixel(int x, int y, bool on_object, const glm::vec3& got, const dvec3& want, double tol) {
    (on_object ? checked_object : checked_plane)++;
    double err =
        std::max({std::abs(got.x - want.x), std::abs(got.y - want.y), std::abs(got.z - want.z)});
    if (err <= tol) return;
    ++failed;
    if (err - tol > worst_excess) {
      worst_excess = err - tol;
      std::ostringstream os;
      os << "(" << x << ", " << y << ") " << (on_object ? "object" : "plane") << ": got (" << got.x
         << ", " << got.y << ", " << got.z << "), formula (" << want.x << ", " << want.y << ", "
         << want.z << "), tolerance " << tol;
      worst = os.str();
    }
  }
  std::string summary() const {
    return std::to_string(failed) + " of " + std::to_string(checked_plane + checked_object) +
           " pixels off the formula; worst " + worst;
  }
};

// A label per image position (surface, shadow side, reflected object...; -1 undecidable); a
// pixel is checked when the 3x3 samples at 0 and +-kEdgeMarginPx around its centre share one.
bool away_from_edges(int x, int y, const std::function<int(double, double)>& label) {
  int centre = label(x + 0.5, y + 0.5);
  if (centre < 0) return false;
  for (double dy : {-kEdgeMarginPx, 0.0, kEdgeMarginPx})
    for (double dx : {-kEdgeMarginPx, 0.0, kEdgeMarginPx})
      if (label(x + 0.5 + dx, y + 0.5 + dy) != centre) return false;
  return true;
}

Scene base_scene(int w, int h, glm::vec3 eye, glm::vec3 target, float fov) {
  Scene s;
  s.source = "test";
  s.image.width = w;
  s.image.height = h;
  s.image.background = {0.1f, 0.15f, 0.2f};
  s.camera.eye = eye;
  s.camera.target = target;
  s.camera.fov_y_deg = fov;
  s.camera.near = 0.1f;
  s.camera.far = 50.0f;
  s.camera.focus_distance = glm::length(target - eye);
  s.materials.push_back(default_material());
  return s;
}

uint32_t add_material(Scene& s, glm::vec3 diffuse, glm::vec3 specular, glm::vec3 emission,
                      float shininess, float mirror = 0.0f) {
  Material m;
  m.diffuse = diffuse;
  m.specular = specular;
  m.emission = emission;
  m.shininess = shininess;
  m.mirror = mirror;
  s.materials.push_back(m);
  return uint32_t(s.materials.size() - 1);
}

void add_plane(Scene& s, float half_size, uint32_t material) {
  Object o;
  o.type = ObjectType::Plane;
  o.plane = {glm::vec3(0.0f), glm::vec3(0, 1, 0), half_size};
  o.material = material;
  s.objects.push_back(o);
}

void add_sphere(Scene& s, glm::vec3 centre, float radius, uint32_t material) {
  Object o;
  o.type = ObjectType::Sphere;
  o.sphere = {centre, radius};
  o.material = material;
  s.objects.push_back(o);
}

void add_disc(Scene& s, glm::vec3 centre, glm::vec3 normal, float radius, uint32_t material) {
  Object o;
  o.type = ObjectType::Disc;
  o.disc = {centre, normal, radius};
  o.material = material;
  s.objects.push_back(o);
}

void add_point_light(Scene& s, glm::vec3 position, glm::vec3 intensity) {
  Light l;
  l.position = position;
  l.intensity = intensity;
  s.lights.push_back(l);
}

// The plane (object 0) under the sphere (object 1); specular on both; 1-3 point lights at
// known places, the first high on the right, the second low on the left, the third near the
// camera.
Scene sphere_on_plane(float shininess, int light_count) {
  Scene s = base_scene(96, 72, {0, 1.6f, 4.2f}, {0, 0.4f, 0}, 40);
  s.ambient = {0.04f, 0.05f, 0.06f};
  add_plane(s, 2.5f,
            add_material(s, {0.55f, 0.5f, 0.45f}, glm::vec3(0.35f), {0.01f, 0.02f, 0}, shininess));
  add_sphere(s, {0.2f, 0.65f, 0}, 0.65f,
             add_material(s, {0.2f, 0.45f, 0.7f}, glm::vec3(0.5f), {0.02f, 0, 0.01f}, shininess));
  const glm::vec3 at[3] = {{2, 3, 2.5f}, {-2.5f, 1.8f, 1.5f}, {0.6f, 1.0f, 2.6f}};
  const glm::vec3 intensity[3] = {glm::vec3(6.0f), {2.5f, 1.5f, 0.8f}, {0.6f, 0.8f, 1.2f}};
  for (int i = 0; i < light_count; ++i) add_point_light(s, at[i], intensity[i]);
  return s;
}

// Parameter: a table entry or variant by name, so that ctest names the case by it.
class ClosedForm : public ::testing::TestWithParam<std::string> {
 protected:
  RendererChoice choice() const {
    Expected<RendererChoice> c = find_renderer_choice(GetParam());
    EXPECT_TRUE(c.ok()) << GetParam();
    return c.value();
  }
};

std::vector<std::string> renderer_choice_names() {
  std::vector<std::string> names;
  for (const RendererChoice& c : renderer_choices()) names.push_back(c.name);
  return names;
}

// Local mode, point lights: emission + ambient * diffuse + Lambert + Blinn-Phong over 1/d^2,
// for shininess 1, 8 and 64 and one, two and three lights.
TEST_P(ClosedForm, PointLightsMatchTheShadingEquation) {
  const RendererChoice choice = this->choice();
  for (float shininess : {1.0f, 8.0f, 64.0f}) {
    for (int light_count = 1; light_count <= 3; ++light_count) {
      SCOPED_TRACE("shininess " + std::to_string(shininess) + ", " + std::to_string(light_count) +
                   " lights");
      Scene s = sphere_on_plane(shininess, light_count);
      RenderedFrame f = render(choice, s, RenderMode::Local);
      ASSERT_EQ(f.buffers.colour.size(), size_t(s.image.width * s.image.height));
      std::vector<PointLight> lights = point_lights(s);
      auto surface = [&](double px, double py) { return trace(s, px, py).object; };
      Check check;
      for (int y = 0; y < s.image.height; ++y) {
        for (int x = 0; x < s.image.width; ++x) {
          if (!away_from_edges(x, y, surface)) continue;
          SurfacePoint sp = trace(s, x + 0.5, y + 0.5);
          size_t i = size_t(y) * s.image.width + x;
          if (sp.object < 0) {
            EXPECT_EQ(f.buffers.object_id[i], kNoId) << x << ", " << y;
            check.pixel(x, y, false, f.buffers.colour[i], dvec3(s.image.background), kTolerance);
            continue;
          }
          EXPECT_EQ(f.buffers.object_id[i], uint32_t(sp.object)) << x << ", " << y;
          const Object& o = s.objects[size_t(sp.object)];
          auto colour = [&](const dvec3& P, const dvec3& N) {
            return oracle::local_colour(s.materials[o.material], dvec3(s.ambient), P, N,
                                        sp.ray.origin, lights);
          };
          bool sphere = o.type == ObjectType::Sphere;
          double tol = kTolerance;
          if (sphere && draws_sphere_meshes(choice)) {
            std::optional<TessellationBound> b = tessellation_bound(sp, o.sphere.radius);
            if (!b) continue;
            tol = tessellation_tolerance(sp, *b, colour);
          }
          check.pixel(x, y, sphere, f.buffers.colour[i], colour(sp.P, sp.N), tol);
        }
      }
      // Enough of each surface is checked for the comparison to mean something.
      EXPECT_GT(check.checked_plane, 2000u);
      EXPECT_GT(check.checked_object, 400u);
      EXPECT_EQ(check.failed, 0u) << check.summary();
    }
  }
}

// Local mode, two discs over the plane: one facing the camera, one tilted away from it and seen
// from its back. The z-buffers draw each as a fan of 64 triangles whose outer edges touch the
// circle, so the fan lies in the disc's plane and around it (beyond it by at most
// r (1 / cos(pi / 64) - 1), 0.001 here, far inside the 1.5 px margin): away from the rim every
// renderer shades the exact disc point with the exact normal, to kTolerance.
TEST_P(ClosedForm, DiscsMatchTheShadingEquation) {
  const RendererChoice choice = this->choice();
  Scene s = base_scene(96, 72, {0, 1.6f, 4.2f}, {0, 0.4f, 0}, 40);
  s.ambient = {0.04f, 0.05f, 0.06f};
  add_plane(s, 2.5f, add_material(s, {0.55f, 0.5f, 0.45f}, glm::vec3(0.35f), {0.01f, 0.02f, 0}, 8));
  const uint32_t disc_material =
      add_material(s, {0.2f, 0.45f, 0.7f}, glm::vec3(0.5f), {0.02f, 0, 0.01f}, 32);
  add_disc(s, {-0.7f, 0.7f, 0.3f}, glm::normalize(glm::vec3(0.1f, 0.3f, 1.0f)), 0.6f,
           disc_material);
  add_disc(s, {0.8f, 0.6f, -0.2f}, glm::normalize(glm::vec3(0.6f, 0.5f, -1.0f)), 0.55f,
           disc_material);
  add_point_light(s, {2, 3, 2.5f}, glm::vec3(6.0f));
  add_point_light(s, {-2.5f, 1.8f, 1.5f}, {2.5f, 1.5f, 0.8f});
  RenderedFrame f = render(choice, s, RenderMode::Local);
  ASSERT_EQ(f.buffers.colour.size(), size_t(s.image.width * s.image.height));
  std::vector<PointLight> lights = point_lights(s);
  auto surface = [&](double px, double py) { return trace(s, px, py).object; };
  Check check;
  size_t checked_back = 0;
  for (int y = 0; y < s.image.height; ++y) {
    for (int x = 0; x < s.image.width; ++x) {
      if (!away_from_edges(x, y, surface)) continue;
      SurfacePoint sp = trace(s, x + 0.5, y + 0.5);
      size_t i = size_t(y) * s.image.width + x;
      if (sp.object < 0) continue;
      EXPECT_EQ(f.buffers.object_id[i], uint32_t(sp.object)) << x << ", " << y;
      const Object& o = s.objects[size_t(sp.object)];
      const bool disc = o.type == ObjectType::Disc;
      checked_back += disc && glm::dot(dvec3(o.disc.normal), sp.N) < 0;
      check.pixel(x, y, disc, f.buffers.colour[i],
                  oracle::local_colour(s.materials[o.material], dvec3(s.ambient), sp.P, sp.N,
                                       sp.ray.origin, lights),
                  kTolerance);
    }
  }
  EXPECT_GT(check.checked_plane, 2000u);
  EXPECT_GT(check.checked_object, 400u);
  EXPECT_GT(checked_back, 100u);  // the tilted disc is seen from behind
  EXPECT_EQ(check.failed, 0u) << check.summary();
}

// The sphere (object 1) over the plane (object 0), one point light: in full mode the plane is
// shadowed where the segment to the light meets the sphere (shadow maps in the z-buffers,
// shadow rays in the tracers); in local mode nowhere.
Scene shadow_scene(float plane_mirror) {
  Scene s = base_scene(96, 72, {0, 2.0f, 3.6f}, {0, 0.3f, 0}, 45);
  s.ambient = {0.05f, 0.05f, 0.05f};
  add_plane(s, 2.5f,
            add_material(s, glm::vec3(0.6f), glm::vec3(0.2f), glm::vec3(0.0f), 16, plane_mirror));
  add_sphere(s, {0, 0.8f, 0}, 0.5f,
             add_material(s, glm::vec3(0.0f), glm::vec3(0.0f), {0.9f, 0.3f, 0.1f}, 16));
  add_point_light(s, {0.8f, 3.0f, -0.4f}, glm::vec3(8.0f));
  return s;
}

// The pixels of a shadow_scene frame away from label's edges: the emissive sphere (its
// emission exactly) and the background are checked here, plane pixels handed to
// on_plane(x, y, point, the renderer's colour).
template <class Label, class OnPlane>
void check_shadow_scene(const Scene& s, const RenderedFrame& f, const Label& label, Check& check,
                        const OnPlane& on_plane) {
  for (int y = 0; y < s.image.height; ++y) {
    for (int x = 0; x < s.image.width; ++x) {
      if (!away_from_edges(x, y, label)) continue;
      SurfacePoint sp = trace(s, x + 0.5, y + 0.5);
      const glm::vec3& got = f.buffers.colour[size_t(y) * s.image.width + x];
      if (sp.object != 0) {
        dvec3 want = sp.object < 0 ? dvec3(s.image.background) : dvec3(0.9, 0.3, 0.1);
        check.pixel(x, y, sp.object == 1, got, want, kTolerance);
        continue;
      }
      on_plane(x, y, sp, got);
    }
  }
}

// Full mode, plane pixels well inside or outside the analytic shadow: ambient alone, or the
// whole local term. The sphere is pure emission, so its pixels are its emission exactly.
TEST_P(ClosedForm, PointLightShadowOfASphereOnAPlane) {
  const RendererChoice choice = this->choice();
  Scene s = shadow_scene(0.0f);
  RenderedFrame f = render(choice, s, RenderMode::Full);
  ASSERT_EQ(f.buffers.colour.size(), size_t(s.image.width * s.image.height));
  std::vector<PointLight> lights = point_lights(s);
  const Sphere& occluder = s.objects[1].sphere;
  auto label = [&](double px, double py) {
    SurfacePoint sp = trace(s, px, py);
    if (sp.object != 0) return sp.object + 1;
    int lit = lit_by(sp.P, lights[0].position, occluder);
    return lit < 0 ? -1 : 10 + lit;
  };
  Check check;
  size_t shadowed = 0;
  check_shadow_scene(
      s, f, label, check, [&](int x, int y, const SurfacePoint& sp, const glm::vec3& got) {
        double lit = lit_by(sp.P, lights[0].position, occluder);
        shadowed += lit == 0;
        dvec3 want = oracle::local_colour(s.materials[s.objects[0].material], dvec3(s.ambient),
                                          sp.P, sp.N, sp.ray.origin, lights, {lit});
        check.pixel(x, y, false, got, want, kTolerance);
      });
  EXPECT_GT(shadowed, 100u) << "the shadow must be in view";
  EXPECT_GT(check.checked_plane, 2000u);
  EXPECT_EQ(check.failed, 0u) << check.summary();
}

// Full mode, the plane a 75% mirror: the tracers (and the hybrids, whose secondary rays are the
// tracer's) show 0.25 * local (shadow included) + 0.75 * what the reflected ray meets: the
// emissive sphere's emission or the background. The z-buffers show the same: the plane is
// flat, so they draw its reflection as a view through the mirrored camera (planar_mirrors.h),
// and the sphere's tessellation differs from the sphere only near its outline, which the
// labels leave out.
TEST_P(ClosedForm, MirrorPlaneReflectsAnEmissiveSphere) {
  const RendererChoice choice = this->choice();
  Scene s = shadow_scene(0.75f);
  RenderedFrame f = render(choice, s, RenderMode::Full);
  ASSERT_EQ(f.buffers.colour.size(), size_t(s.image.width * s.image.height));
  std::vector<PointLight> lights = point_lights(s);
  const Sphere& sphere = s.objects[1].sphere;
  auto reflects_sphere = [&](const SurfacePoint& sp) {
    oracle::Ray r{sp.P, sp.ray.direction - 2 * glm::dot(sp.ray.direction, sp.N) * sp.N};
    return oracle::hit_sphere(r, sphere).has_value();
  };
  auto label = [&](double px, double py) {
    SurfacePoint sp = trace(s, px, py);
    if (sp.object != 0) return sp.object + 1;
    int lit = lit_by(sp.P, lights[0].position, sphere);
    return lit < 0 ? -1 : 10 + 2 * lit + int(reflects_sphere(sp));
  };
  Check check;
  size_t reflecting = 0;
  check_shadow_scene(
      s, f, label, check, [&](int x, int y, const SurfacePoint& sp, const glm::vec3& got) {
        double lit = lit_by(sp.P, lights[0].position, sphere);
        dvec3 local = oracle::local_colour(s.materials[s.objects[0].material], dvec3(s.ambient),
                                           sp.P, sp.N, sp.ray.origin, lights, {lit});
        bool hit = reflects_sphere(sp);
        reflecting += hit;
        dvec3 reflected = hit ? dvec3(0.9, 0.3, 0.1) : dvec3(s.image.background);
        dvec3 want = 0.25 * local + 0.75 * reflected;
        check.pixel(x, y, false, got, want, kTolerance);
      });
  EXPECT_GT(reflecting, 50u) << "the sphere's reflection must be in view";
  EXPECT_GT(check.checked_plane, 2000u);
  EXPECT_EQ(check.failed, 0u) << check.summary();
}

// Local mode, a square area light of side a = 0.5 and total intensity I, parallel to the plane
// at height H = 2, sampled as n x n = 8 x 8 points at the centres of its cells, each I / n^2.
// The diffuse light at a plane point P is then the midpoint rule for
//   kd * (I / a^2) * integral over the square of cos(theta) / d^2 = kd * (I / a^2) * Omega(P),
// cos(theta) = H / d, and H / d^3 dA is the solid-angle element of the parallel square: Omega
// is the square's solid angle seen from P, in closed form (oracle::rectangle_solid_angle).
// The midpoint rule on cells of side delta errs by at most area * delta^2 / 24 * (max |f_xx| +
// max |f_zz|) for f = H / d^3, whose second derivatives are at most 3 / H^4 in size (at the
// foot point), so the colour may differ from the closed form by kd * I * delta^2 / (4 H^4).
TEST_P(ClosedForm, SquareAreaLightOnAPlaneIsItsSolidAngle) {
  const RendererChoice choice = this->choice();
  Scene s = base_scene(80, 60, {0, 3.5f, 3.0f}, {0, 0, 0}, 50);
  s.ambient = {0.03f, 0.03f, 0.03f};
  const glm::vec3 kd(0.7f, 0.6f, 0.5f);
  add_plane(s, 2.5f, add_material(s, kd, glm::vec3(0.0f), {0.01f, 0, 0}, 16));
  const double a = 0.5, H = 2.0, I = 10.0;
  const int n = 8;
  Light area;
  area.type = LightType::Area;
  area.corner = {-0.25f, float(H), -0.25f};
  area.edge_u = {float(a), 0, 0};
  area.edge_v = {0, 0, float(a)};
  area.intensity = glm::vec3(float(I));
  area.samples = n;
  s.lights = {area};
  RenderedFrame f = render(choice, s, RenderMode::Local);
  ASSERT_EQ(f.buffers.colour.size(), size_t(s.image.width * s.image.height));
  const double delta = a / n;
  const double midpoint_bound = double(kd.x) * I * delta * delta / (4 * H * H * H * H);
  auto surface = [&](double px, double py) { return trace(s, px, py).object; };
  Check check;
  for (int y = 0; y < s.image.height; ++y) {
    for (int x = 0; x < s.image.width; ++x) {
      if (!away_from_edges(x, y, surface)) continue;
      SurfacePoint sp = trace(s, x + 0.5, y + 0.5);
      if (sp.object != 0) continue;
      double omega = oracle::rectangle_solid_angle(-0.25 - sp.P.x, 0.25 - sp.P.x, -0.25 - sp.P.z,
                                                   0.25 - sp.P.z, H);
      dvec3 want =
          dvec3(0.01, 0, 0) + dvec3(s.ambient) * dvec3(kd) + dvec3(kd) * (I / (a * a)) * omega;
      size_t i = size_t(y) * s.image.width + x;
      check.pixel(x, y, false, f.buffers.colour[i], want, kTolerance + midpoint_bound);
    }
  }
  EXPECT_GT(check.checked_plane, 2000u);
  EXPECT_EQ(check.failed, 0u) << check.summary();
}

INSTANTIATE_TEST_SUITE_P(EveryRenderer, ClosedForm, ::testing::ValuesIn(renderer_choice_names()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

// The z-buffers' tessellation, counted from its closed form rather than the code's own formula:
// a UV sphere of S longitudes and S/2 rings has two polar caps of S triangles and S/2 - 2
// bands of 2 S triangles, S * (S - 2) in all; the square is two triangles. A dropped triangle
// leaves a hole no image test may look at.
TEST(ClosedFormTessellation, TriangleCountsFollowTheirClosedForms) {
  for (int S : {4, 8, 48, 64}) {
    TriangleMesh m = tessellate_sphere({glm::vec3(0.0f), 1.0f}, S);
    EXPECT_EQ(m.triangle_count(), size_t(2 * S + (S / 2 - 2) * 2 * S)) << S << " segments";
  }
  EXPECT_EQ(tessellate_plane({glm::vec3(0.0f), glm::vec3(0, 1, 0), 1.0f}).triangle_count(), 2u);
}

// The same without counting: a closed surface has every edge in exactly two triangles, once
// in each direction (counter-clockwise from outside); a dropped triangle leaves edges without
// their twin.
TEST(ClosedFormTessellation, SphereMeshIsClosed) {
  TriangleMesh m = tessellate_sphere({glm::vec3(0.0f), 1.0f}, 16);
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const glm::uvec3& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << edge.first << "->" << edge.second;
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u)
        << "edge " << edge.first << "->" << edge.second << " has no twin: a hole";
  }
}

// The disc's fan: S triangles, every one facing the disc's normal (counter-clockwise seen from
// its side), the corners at r / cos(pi / S) from the centre so that every outer edge touches the
// circle at its midpoint, and the fan's area the circumscribed regular S-gon's,
// S r^2 tan(pi / S): no triangle dropped, doubled or folded over another.
TEST(ClosedFormTessellation, DiscFanIsTheCircumscribedRegularPolygon) {
  const Disc disc{{0.5f, -1.0f, 2.0f}, glm::normalize(glm::vec3(1.0f, 2.0f, -0.5f)), 1.5f};
  const dvec3 centre(disc.center);
  for (int S : {3, 8, 64}) {
    SCOPED_TRACE(std::to_string(S) + " segments");
    TriangleMesh m = tessellate_disc(disc, S);
    ASSERT_EQ(m.triangle_count(), size_t(S));
    EXPECT_EQ(disc.triangle_count({S, false}), uint64_t(S));
    double area = 0;
    for (const glm::uvec3& t : m.triangles) {
      dvec3 a(m.positions[t.x]), b(m.positions[t.y]), c(m.positions[t.z]);
      dvec3 n = glm::cross(b - a, c - a);
      EXPECT_GT(glm::dot(n, dvec3(disc.normal)), 0.0);
      area += 0.5 * glm::length(n);
      EXPECT_NEAR(glm::length(0.5 * (b + c) - centre), 1.5, 1e-5);  // the outer edge's midpoint
    }
    for (size_t v = 1; v < m.positions.size(); ++v)
      EXPECT_NEAR(glm::length(dvec3(m.positions[v]) - centre), 1.5 / std::cos(kPi / S), 1e-5);
    EXPECT_NEAR(area, S * 1.5 * 1.5 * std::tan(kPi / S), 1e-4);
  }
}

}  // namespace
}  // namespace rvr
