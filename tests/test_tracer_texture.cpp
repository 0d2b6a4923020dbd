// The tracer's textures and vertex colours against closed forms: on a checker-textured plane
// seen at grazing angles, the level of detail of each pixel from the ray-plane intersection
// worked out in double precision (ray differentials: GL's formula on the exact uv derivatives;
// ray cones: the chapter's lambda = delta + log2(spread t / |cos theta|)); level 0 sampled
// bilinearly with --texture-lod none; a vertex-coloured triangle interpolated per pixel, seen
// directly and in a mirror.
#include <gtest/gtest.h>
#include <stdint.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/glm.hpp>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/surface_colour.h"
#include "rvr/core/texture.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/scene_io/scene_loader.h"
#include "scene_builders.h"

using namespace rvr;
using namespace rvr::test;

namespace {

constexpr int kTexels = 64;        // the checker texture's side
constexpr double kHalf = 40.0;     // the plane spans [-kHalf, kHalf] in x and z, at y = 0
constexpr double kRepeats = 32.0;  // uv runs 0 .. kRepeats across it
constexpr double kUvPerUnit = kRepeats / (2.0 * kHalf);

// 8-texel squares of two colours.
glm::vec3 checker_texel(int x, int y) {
  return ((x / 8 + y / 8) % 2 == 0) ? glm::vec3(0.9f, 0.8f, 0.7f) : glm::vec3(0.1f, 0.2f, 0.4f);
}

Texture checker_texture() {
  TextureLevel level;
  level.width = level.height = kTexels;
  for (int y = 0; y < kTexels; ++y)
    for (int x = 0; x < kTexels; ++x) level.texels.push_back(checker_texel(x, y));
  Texture t;
  t.file = "checker";
  t.mips = std::make_shared<const MipChain>(build_mip_chain(std::move(level)));
  return t;
}

// The textured plane y = 0 (two triangles, uv = ((x + kHalf), (kHalf - z)) * kUvPerUnit), white,
// lit by an ambient of 1 alone: a pixel's colour is its base colour.
Scene textured_plane(glm::vec3 eye, glm::vec3 target, int w, int h) {
  Scene s = empty_scene(w, h, eye, target, 50.0f);
  s.camera.far = 1000.0f;
  s.textures.push_back(checker_texture());
  const uint32_t m = add_material(s, glm::vec3(1.0f));
  s.materials[m].texture = 0;
  s.ambient = glm::vec3(1.0f);
  Object o;
  o.type = ObjectType::Triangles;
  o.material = m;
  const float k = float(kHalf), r = float(kRepeats);
  o.mesh.positions = {{-k, 0, k}, {k, 0, k}, {k, 0, -k}, {-k, 0, -k}};
  o.mesh.uvs = {{0, 0}, {r, 0}, {r, r}, {0, r}};
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(o);
  return s;
}

// A grazing view: the eye half a unit above the plane, looking almost level, so that rows run
// from a steep view at the bottom to the horizon.
Scene grazing_plane() {
  return textured_plane({0.0f, 0.5f, 30.0f}, {0.0f, 0.2f, 0.0f}, 96, 64);
}

RenderOutput trace(const Scene& s, RenderMode mode, TextureLod lod,
                   AccelKind accel = AccelKind::Bvh) {
  RayTracer tracer;
  RenderOptions o;
  o.mode = mode;
  o.texture_lod = lod;
  o.accel = accel;
  Expected<RenderOutput> out = tracer.render(s, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return std::move(out).value();
}

// The camera in double precision: the pixel-centre ray of (x, y) and its derivatives along the
// pixel grid (camera_ray_direction's expressions).
struct ExactCamera {
  glm::dvec3 eye, forward, right, up;
  double tan_half, aspect;
  int width, height;

  explicit ExactCamera(const Scene& s)
      : eye(s.camera.eye),
        forward(glm::normalize(glm::dvec3(s.camera.target) - glm::dvec3(s.camera.eye))),
        right(glm::normalize(glm::cross(forward, glm::dvec3(s.camera.up)))),
        up(glm::cross(right, forward)),
        tan_half(std::tan(double(s.camera.fov_y_deg) * M_PI / 360.0)),
        aspect(double(s.image.width) / double(s.image.height)),
        width(s.image.width),
        height(s.image.height) {}

  glm::dvec3 direction(int x, int y) const {
    const double ndc_x = 2.0 * (x + 0.5) / width - 1.0, ndc_y = 1.0 - 2.0 * (y + 0.5) / height;
    return forward + right * (ndc_x * tan_half * aspect) + up * (ndc_y * tan_half);
  }
  glm::dvec3 d_dx() const { return right * (2.0 * tan_half * aspect / width); }
  glm::dvec3 d_dy() const { return up * (-2.0 * tan_half / height); }
};

// Where the centre ray of (x, y) meets the plane y = 0, and the uv derivatives per pixel there:
// P = eye + t D with t = -eye.y / D.y, so dP = t dD + dt D with dt = -t dD.y / D.y; uv is affine
// in P with du = dx kUvPerUnit, dv = -dz kUvPerUnit.
struct PlaneHit {
  bool inside = false;  // on the plane, a margin inside its edges
  glm::dvec3 D, P;
  double t = 0;
  glm::dvec2 uv, duv_dx, duv_dy;
};

PlaneHit hit_plane(const ExactCamera& c, int x, int y) {
  PlaneHit h;
  h.D = c.direction(x, y);
  if (!(h.D.y < 0.0)) return h;
  h.t = -c.eye.y / h.D.y;
  h.P = c.eye + h.t * h.D;
  h.inside = std::abs(h.P.x) < kHalf - 0.5 && std::abs(h.P.z) < kHalf - 0.5;
  h.uv = {(h.P.x + kHalf) * kUvPerUnit, (kHalf - h.P.z) * kUvPerUnit};
  auto duv = [&](const glm::dvec3& dD) {
    const double dt = -h.t * dD.y / h.D.y;
    const glm::dvec3 dP = h.t * dD + dt * h.D;
    return glm::dvec2(dP.x * kUvPerUnit, -dP.z * kUvPerUnit);
  };
  h.duv_dx = duv(c.d_dx());
  h.duv_dy = duv(c.d_dy());
  return h;
}

// GL's level of detail on the exact derivatives.
double exact_differentials_lod(const PlaneHit& h) {
  return std::log2(std::max(glm::length(h.duv_dx), glm::length(h.duv_dy)) * kTexels);
}

// The chapter's: delta = 0.5 log2(texels * uv area / world area) (the plane maps area by
// kUvPerUnit^2 everywhere), the primary cone's width at distance |t D|, theta between the ray
// and the plane's normal (0, 1, 0).
double exact_cone_lod(const ExactCamera& c, const PlaneHit& h) {
  const double spread = std::atan(2.0 * c.tan_half / c.height);
  const double delta = 0.5 * std::log2(double(kTexels) * kTexels * kUvPerUnit * kUvPerUnit);
  const double distance = h.t * glm::length(h.D);
  const double cos_theta = h.D.y / glm::length(h.D);
  return delta + std::log2(spread * distance / std::abs(cos_theta));
}

// How far the float pipeline may stray from the exact lod at a pixel. The tracer's ray
// direction, hit distance and derivatives each carry a few float roundings (relative 2^-24
// each) of quantities of the size of |D|; where the ray grazes the plane they are divided by
// D.y (the hit distance t = -eye.y / D.y, the transfer's (D . N)), which magnifies a rounding
// of |D|'s size by |D| / |D.y|. A relative error e of rho moves log2(rho) by e / ln 2. 64
// roundings at that magnification bound the chain (the transfer and the barycentric solve
// take about 40 operations) with room, and stay far below any error a wrong formula makes
// (a wrong axis, a missing cos theta: whole fractions of a mip level).
double lod_tolerance(const PlaneHit& h) {
  const double rounding = std::ldexp(1.0, -24);
  return 64.0 * rounding * (glm::length(h.D) / std::abs(h.D.y)) / std::log(2.0);
}

// Checks the lod AOV against `expected` at every pixel whose centre ray meets the plane inside
// its edges; returns how many were checked.
template <class Formula>
int check_lod(const Scene& s, const RenderOutput& out, const Formula& expected) {
  const ExactCamera c(s);
  EXPECT_EQ(out.buffers.lod.size(), out.buffers.pixel_count());
  if (out.buffers.lod.size() != out.buffers.pixel_count()) return 0;
  int checked = 0;
  double worst = 0;
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const size_t i = out.buffers.index(x, y);
      const PlaneHit h = hit_plane(c, x, y);
      if (!h.inside) {
        if (out.buffers.object_id[i] == kNoId) {
          EXPECT_TRUE(std::isnan(out.buffers.lod[i]));
        }
        continue;
      }
      EXPECT_EQ(out.buffers.object_id[i], 0u) << x << "," << y;
      const double want = expected(c, h), got = out.buffers.lod[i];
      EXPECT_NEAR(got, want, lod_tolerance(h)) << "pixel " << x << "," << y;
      worst = std::max(worst, std::abs(got - want));
      ++checked;
    }
  std::printf("lod checked at %d pixels, largest |error| %.3g mip levels\n", checked, worst);
  return checked;
}

}  // namespace

TEST(TracerTexture, DifferentialsGiveTheExactMipLevelOnAGrazingPlane) {
  const Scene s = grazing_plane();
  for (RenderMode mode : {RenderMode::Local, RenderMode::Full}) {
    const RenderOutput out = trace(s, mode, TextureLod::Differentials);
    const int checked = check_lod(
        s, out, [](const ExactCamera&, const PlaneHit& h) { return exact_differentials_lod(h); });
    // The view spans many levels: from magnified (lod < 0) at the bottom to the last levels
    // near the horizon.
    EXPECT_GT(checked, 96 * 20);
    const ExactCamera c(s);
    EXPECT_LT(exact_differentials_lod(hit_plane(c, 48, 63)), 0.0);
    EXPECT_GT(exact_differentials_lod(hit_plane(c, 48, 33)), 3.0);
  }
}

TEST(TracerTexture, ConesGiveTheChaptersClosedFormOnAGrazingPlane) {
  const Scene s = grazing_plane();
  for (RenderMode mode : {RenderMode::Local, RenderMode::Full, RenderMode::Visibility}) {
    const RenderOutput out = trace(s, mode, TextureLod::Cones);
    EXPECT_GT(check_lod(s, out, exact_cone_lod), 96 * 20);
  }
}

// GL's LINEAR on level 0, worked out here: texel centres at (i + 0.5) / size, Repeat wrap.
glm::dvec3 exact_bilinear(glm::dvec2 uv) {
  const double fx = uv.x * kTexels - 0.5, fy = uv.y * kTexels - 0.5;
  const double x0 = std::floor(fx), y0 = std::floor(fy);
  const double ax = fx - x0, ay = fy - y0;
  auto texel = [](double x, double y) {
    const int wx = int(((long long)x % kTexels + kTexels) % kTexels);
    const int wy = int(((long long)y % kTexels + kTexels) % kTexels);
    return glm::dvec3(checker_texel(wx, wy));
  };
  return (1 - ay) * ((1 - ax) * texel(x0, y0) + ax * texel(x0 + 1, y0)) +
         ay * ((1 - ax) * texel(x0, y0 + 1) + ax * texel(x0 + 1, y0 + 1));
}

TEST(TracerTexture, NoneSamplesLevelZeroBilinearly) {
  // A steeper view, where the float uv stays within a thousandth of a texel of the exact one.
  const Scene s = textured_plane({0.0f, 6.0f, 12.0f}, {0.0f, 0.0f, 0.0f}, 64, 48);
  const ExactCamera c(s);
  for (RenderMode mode : {RenderMode::Local, RenderMode::Full}) {
    const RenderOutput out = trace(s, mode, TextureLod::None);
    int checked = 0;
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x) {
        const PlaneHit h = hit_plane(c, x, y);
        if (!h.inside) continue;
        const size_t i = out.buffers.index(x, y);
        ASSERT_EQ(out.buffers.lod[i], 0.0f) << x << "," << y;
        // Colour slope: at most 0.8 per texel; uv error: under 1e-3 texels here.
        const glm::dvec3 want = exact_bilinear(h.uv);
        for (int a = 0; a < 3; ++a)
          EXPECT_NEAR(out.buffers.colour[i][a], want[a], 1e-3) << x << "," << y << " channel " << a;
        ++checked;
      }
    EXPECT_GT(checked, 64 * 40);
  }
}

// A triangle with red, green and blue corners facing the camera, lit by an ambient of 1 alone
// (its colour is its interpolated vertex colour), and optionally a mirror floor below it.
Scene vertex_coloured_triangle(bool mirror_floor) {
  Scene s = empty_scene(61, 61, {0.0f, 1.0f, 6.0f}, {0.0f, 1.0f, 0.0f}, 40.0f);
  s.ambient = glm::vec3(1.0f);
  Object t;
  t.type = ObjectType::Triangles;
  t.material = add_material(s, glm::vec3(1.0f));
  t.mesh.positions = {{-1.5f, 0.2f, 0.0f}, {1.5f, 0.2f, 0.0f}, {0.0f, 2.2f, 0.0f}};
  t.mesh.colours = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  t.mesh.triangles = {{0, 1, 2}};
  s.objects.push_back(t);
  if (mirror_floor)
    add_plane(s, {0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 20.0f,
              add_material(s, glm::vec3(0.0f), glm::vec3(0.0f), 1.0f));
  return s;
}

// The interpolated vertex colour where the ray eye + t D meets the triangle's plane z = 0 (its
// corners as in vertex_coloured_triangle), or nothing outside it (with a margin).
std::optional<glm::dvec3> exact_vertex_colour(const glm::dvec3& eye, const glm::dvec3& D) {
  const double t = -eye.z / D.z;
  const glm::dvec3 P = eye + t * D;
  // Barycentrics of (x, y) in the triangle (-1.5, 0.2), (1.5, 0.2), (0, 2.2).
  const double b2 = (P.y - 0.2) / 2.0;
  const double b1 = (P.x + 1.5 - 1.5 * b2) / 3.0;
  const double b0 = 1.0 - b1 - b2;
  if (std::min({b0, b1, b2}) < 0.02) return std::nullopt;
  return glm::dvec3(b0, b1, b2);  // red b0 + green b1 + blue b2
}

TEST(TracerTexture, VertexColoursAreInterpolatedPerPixel) {
  const Scene s = vertex_coloured_triangle(false);
  const ExactCamera c(s);
  for (RenderMode mode : {RenderMode::Local, RenderMode::Full}) {
    const RenderOutput out = trace(s, mode, TextureLod::Cones);
    EXPECT_TRUE(out.buffers.lod.empty());  // vertex colours only: no texture, no lod AOV
    int checked = 0;
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x) {
        const std::optional<glm::dvec3> want = exact_vertex_colour(c.eye, c.direction(x, y));
        if (!want) continue;
        const glm::vec3 got = out.buffers.colour[out.buffers.index(x, y)];
        for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], (*want)[a], 1e-5) << x << "," << y;
        ++checked;
      }
    EXPECT_GT(checked, 300);
    // The centroid (0, 0.8667, 0) lies on the centre column: its colour is the corners' mean.
    const glm::dvec3 centroid(0.0, (0.2 + 0.2 + 2.2) / 3.0, 0.0);
    const glm::dvec3 to = centroid - c.eye;
    const double py =
        (1.0 - glm::dot(to, c.up) / glm::dot(to, c.forward) / c.tan_half) * 0.5 * c.height;
    const int y = int(std::floor(py));
    const std::optional<glm::dvec3> at = exact_vertex_colour(c.eye, c.direction(30, y));
    ASSERT_TRUE(at.has_value());
    for (int a = 0; a < 3; ++a) EXPECT_NEAR((*at)[a], 1.0 / 3.0, 0.02);
    const glm::vec3 got = out.buffers.colour[out.buffers.index(30, y)];
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], 1.0 / 3.0, 0.02);
  }
}

TEST(TracerTexture, MirrorRaysShadeVertexColours) {
  // Full mode: below the horizon the camera sees the mirror floor, whose reflected rays meet
  // the triangle; their colour is the vertex colour where the mirrored ray lands.
  const Scene s = vertex_coloured_triangle(true);
  const ExactCamera c(s);
  const RenderOutput out = trace(s, RenderMode::Full, TextureLod::Cones);
  int checked = 0;
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const glm::dvec3 D = c.direction(x, y);
      if (!(D.y < 0.0)) continue;
      const double t = -c.eye.y / D.y;
      const glm::dvec3 floor = c.eye + t * D;
      if (floor.z < 0.05) continue;  // behind the triangle's plane, or too close to it
      // The tracer starts the reflected ray a hair above the floor (ray_epsilon).
      const double eps = 1e-4 * std::max({std::abs(floor.x), std::abs(floor.z), 1.0});
      const glm::dvec3 mirrored(D.x, -D.y, D.z);
      const std::optional<glm::dvec3> want =
          exact_vertex_colour(floor + glm::dvec3(0.0, eps, 0.0), mirrored);
      const size_t i = out.buffers.index(x, y);
      if (!want) continue;
      if (exact_vertex_colour(c.eye, D)) continue;  // the triangle itself in front
      const glm::vec3 got = out.buffers.colour[i];
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], (*want)[a], 1e-4) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 100);
}

TEST(TracerTexture, EmbreeFindsTheSameSurfacesColoursAndLevels) {
  Expected<Scene> scene = make_builtin_scene("textured");
  ASSERT_TRUE(scene.ok());
  Scene s = *scene;
  s.image.width = 160;
  s.image.height = 120;
  for (TextureLod lod : {TextureLod::Cones, TextureLod::Differentials}) {
    const RenderOutput ours = trace(s, RenderMode::Local, lod);
    const RenderOutput embree = trace(s, RenderMode::Local, lod, AccelKind::Embree);
    ASSERT_EQ(ours.buffers.lod.size(), ours.buffers.pixel_count());
    ASSERT_EQ(embree.buffers.lod.size(), ours.buffers.pixel_count());
    size_t same_id = 0, textured = 0;
    for (size_t i = 0; i < ours.buffers.pixel_count(); ++i) {
      if (ours.buffers.object_id[i] != embree.buffers.object_id[i]) continue;
      ++same_id;
      // The same base colour at barycentrics that differ by roundings.
      for (int a = 0; a < 3; ++a)
        EXPECT_NEAR(ours.buffers.colour[i][a], embree.buffers.colour[i][a], 1e-3) << i;
      if (std::isnan(ours.buffers.lod[i])) {
        EXPECT_TRUE(std::isnan(embree.buffers.lod[i])) << i;
        continue;
      }
      ++textured;
      // Embree's hit distance and barycentrics differ from ours by roundings only.
      EXPECT_NEAR(ours.buffers.lod[i], embree.buffers.lod[i], 1e-3) << i;
    }
    EXPECT_EQ(same_id, ours.buffers.pixel_count());
    EXPECT_GT(textured, ours.buffers.pixel_count() / 4);
  }
}

// A textured wall z = -5 (uv = (x + 10, y) per unit) standing on a mirror floor y = 0, lit by an
// ambient of 1 alone: below the horizon the camera sees the wall's reflection, whose colour is
// the wall's texture sampled at the reflected ray's level of detail.
Scene wall_over_mirror() {
  Scene s = empty_scene(80, 60, {0.0f, 1.5f, 6.0f}, {0.0f, 0.5f, 0.0f}, 50.0f);
  s.textures.push_back(checker_texture());
  s.ambient = glm::vec3(1.0f);
  Object wall;
  wall.type = ObjectType::Triangles;
  wall.material = add_material(s, glm::vec3(1.0f));
  s.materials[wall.material].texture = 0;
  wall.mesh.positions = {{-10, 0, -5}, {10, 0, -5}, {10, 10, -5}, {-10, 10, -5}};
  wall.mesh.uvs = {{0, 0}, {20, 0}, {20, 10}, {0, 10}};
  wall.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(wall);
  add_plane(s, {0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 20.0f,
            add_material(s, glm::vec3(0.0f), glm::vec3(0.0f), 1.0f));
  return s;
}

// The reflected ray of pixel (x, y) off the mirror floor, worked out in double: it starts at
// the floor point lifted by the tracer's ray_epsilon, along the unit mirrored direction R; its
// footprint is the floor point's derivatives dO (Igehy's transfer onto y = 0) and R's
// derivatives (those of normalize(mirror(D))); carried to the wall's plane z = -5 the same way.
// The level of detail there by either method; nothing where the ray misses the wall.
struct WallSample {
  glm::dvec2 uv;
  double lod_cones, lod_differentials;
};

std::optional<WallSample> exact_wall_sample(const ExactCamera& c, int x, int y) {
  constexpr double kUv = 1.0, kWallZ = -5.0;
  const glm::dvec3 D = c.direction(x, y);
  if (!(D.y < 0.0)) return std::nullopt;
  const double t1 = -c.eye.y / D.y;
  const glm::dvec3 floor = c.eye + t1 * D;
  if (!(floor.z > kWallZ + 0.5) || std::abs(floor.x) > 19.0 || floor.z > 19.0) return std::nullopt;
  auto floor_derivative = [&](const glm::dvec3& dD) { return t1 * dD + (-t1 * dD.y / D.y) * D; };
  const glm::dvec3 M(D.x, -D.y, D.z);  // mirror(D)
  const double m = glm::length(M);
  const glm::dvec3 R = M / m;
  auto unit_derivative = [&](const glm::dvec3& dD) {
    const glm::dvec3 dM(dD.x, -dD.y, dD.z);
    return (dM - glm::dot(R, dM) * R) / m;
  };
  const double eps = 1e-4 * std::max({std::abs(floor.x), std::abs(floor.z), 1.0});
  const glm::dvec3 O = floor + glm::dvec3(0.0, eps, 0.0);
  if (!(R.z < 0.0)) return std::nullopt;
  const double t2 = (kWallZ - O.z) / R.z;
  const glm::dvec3 P = O + t2 * R;
  if (std::abs(P.x) > 9.5 || P.y < 0.5 || P.y > 9.5) return std::nullopt;
  auto wall_duv = [&](const glm::dvec3& dD) {
    const glm::dvec3 dO = floor_derivative(dD), dR = unit_derivative(dD);
    const glm::dvec3 moved = dO + t2 * dR;
    const glm::dvec3 dP = moved - (moved.z / R.z) * R;
    return glm::dvec2(dP.x * kUv, dP.y * kUv);
  };
  WallSample w;
  w.uv = {(P.x + 10.0) * kUv, P.y * kUv};
  const glm::dvec2 dx = wall_duv(c.d_dx()), dy = wall_duv(c.d_dy());
  w.lod_differentials = std::log2(std::max(glm::length(dx), glm::length(dy)) * kTexels);
  // The cone: primary spread, width grown over both legs; theta at the wall, whose normal is z.
  const double spread = std::atan(2.0 * c.tan_half / c.height);
  const double width = spread * (t1 * glm::length(D) + t2);
  w.lod_cones =
      0.5 * std::log2(double(kTexels) * kTexels * kUv * kUv) + std::log2(width / std::abs(R.z));
  return w;
}

TEST(TracerTexture, ReflectedRaysCarryTheirFootprintToTheTexture) {
  const Scene s = wall_over_mirror();
  const ExactCamera c(s);
  const MipChain& mips = *s.textures[0].mips;
  for (TextureLod kind : {TextureLod::Cones, TextureLod::Differentials}) {
    const RenderOutput out = trace(s, RenderMode::Full, kind);
    int checked = 0;
    double spread_of_levels[2] = {1e9, -1e9};
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x) {
        const std::optional<WallSample> w = exact_wall_sample(c, x, y);
        if (!w) continue;
        const double lod = kind == TextureLod::Cones ? w->lod_cones : w->lod_differentials;
        spread_of_levels[0] = std::min(spread_of_levels[0], lod);
        spread_of_levels[1] = std::max(spread_of_levels[1], lod);
        // The texture sampled at the exact uv and level: colours move by at most 0.8 per texel
        // or per level, and the float uv and level stray by far less than 1e-3 of either.
        const glm::vec3 want = sample_trilinear(mips, TextureWrap::Repeat, TextureWrap::Repeat,
                                                glm::vec2(w->uv), float(lod));
        const glm::vec3 got = out.buffers.colour[out.buffers.index(x, y)];
        for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want[a], 1e-3) << x << "," << y;
        ++checked;
      }
    EXPECT_GT(checked, 500);
    std::printf("reflected levels %.3f .. %.3f\n", spread_of_levels[0], spread_of_levels[1]);
    // The reflection is minified, across fractional levels: a wrong footprint shows as a wrong
    // blend of two levels.
    EXPECT_GT(spread_of_levels[0], 1.0);
    EXPECT_GT(spread_of_levels[1] - spread_of_levels[0], 0.2);
  }
}

TEST(TracerTexture, EveryMethodAndModeGivesFiniteColoursAndALevelExactlyWhereTextured) {
  Expected<Scene> scene = make_builtin_scene("textured");
  ASSERT_TRUE(scene.ok());
  Scene s = *scene;
  s.image.width = 80;
  s.image.height = 60;
  s.image.samples_per_pixel = 4;  // the jittered sample rays carry footprints too
  const uint32_t floor = 0;       // builtin:textured's textured floor
  ASSERT_TRUE(textured(s, s.objects[floor]));
  for (TextureLod kind : {TextureLod::Cones, TextureLod::Differentials, TextureLod::None})
    for (RenderMode mode : {RenderMode::Local, RenderMode::Full}) {
      const RenderOutput out = trace(s, mode, kind);
      ASSERT_EQ(out.buffers.lod.size(), out.buffers.pixel_count());
      for (size_t i = 0; i < out.buffers.pixel_count(); ++i) {
        const glm::vec3 c = out.buffers.colour[i];
        EXPECT_TRUE(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z)) << i;
        EXPECT_EQ(std::isnan(out.buffers.lod[i]), out.buffers.object_id[i] != floor) << i;
      }
    }
}

TEST(TracerTexture, SameBytesWithOneAndTwoThreads) {
  Expected<Scene> scene = make_builtin_scene("textured");
  ASSERT_TRUE(scene.ok());
  Scene s = *scene;
  s.image.width = 96;
  s.image.height = 72;
  s.image.samples_per_pixel = 4;
  for (TextureLod kind : {TextureLod::Cones, TextureLod::Differentials}) {
    RenderOutput out[2];
    for (int threads : {1, 2}) {
      RayTracer tracer;
      RenderOptions o;
      o.mode = RenderMode::Full;
      o.texture_lod = kind;
      o.threads = threads;
      Expected<RenderOutput> r = tracer.render(s, o);
      ASSERT_TRUE(r.ok());
      out[threads - 1] = std::move(r).value();
    }
    const size_t n = out[0].buffers.pixel_count();
    EXPECT_EQ(std::memcmp(out[0].buffers.colour.data(), out[1].buffers.colour.data(),
                          n * sizeof(glm::vec3)),
              0);
    EXPECT_EQ(std::memcmp(out[0].buffers.lod.data(), out[1].buffers.lod.data(), n * sizeof(float)),
              0);
  }
}
