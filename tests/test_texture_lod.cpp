// The texture level of detail of the z-buffers against a closed form: a textured plane seen at
// grazing angles by a pinhole camera, every pixel's expected mip level computed here from the
// ray-plane intersection's exact derivative along the pixel axes (in double precision, with
// nothing of the renderers' camera or texture code), against softraster's and GL's lod AOV.
// And builtin:textured in both z-buffers: the same visibility, close colours.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <glm/glm.hpp>
#include <initializer_list>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "closed_form_oracle.h"
#include "rvr/compare/compare.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/texture.h"
#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raster/soft_rasterizer.h"
#include "rvr/scene_io/scene_loader.h"

namespace rvr {
namespace {

using glm::dvec2;
using glm::dvec3;

constexpr int kTexels = 64;           // the checkerboard's side
constexpr double kUvPerWorld = 0.25;  // one repeat every 4 units along x and z
constexpr double kHalfWidth = 100.0, kNearZ = 2.0, kFarZ = -400.0;

// The floor y = 0 from x = -100 to 100 and z = 2 to -400 (two triangles), u = x / 4 and
// v = -z / 4 on a 64x64 checkerboard, Repeat; the eye 1 above it looking a little down and
// turned a little to the right, so the view runs from steep below to grazing at the horizon and
// the depth varies along both image axes.
// `rolled`: the camera turned 90 degrees about its view axis (up = +x), so the horizon is
// vertical and the footprint along the image's x axis is the longer one.
Scene grazing_plane(int width, int height, bool rolled = false) {
  Scene s;
  s.image.width = width;
  s.image.height = height;
  s.camera.eye = {0.0f, 1.0f, 0.0f};
  s.camera.target = {2.5f, 0.8f, -10.0f};
  if (rolled) s.camera.up = {1.0f, 0.0f, 0.0f};
  s.camera.fov_y_deg = 60.0f;
  s.camera.near = 0.05f;
  s.camera.far = 1000.0f;
  s.ambient = glm::vec3(1.0f);
  s.materials.push_back(Material{});
  TextureLevel level;
  level.width = level.height = kTexels;
  for (int y = 0; y < kTexels; ++y)
    for (int x = 0; x < kTexels; ++x)
      level.texels.push_back(((x / 8 + y / 8) % 2) ? glm::vec3(0.9f) : glm::vec3(0.1f));
  Texture t;
  t.file = "checker";
  t.mips = std::make_shared<const MipChain>(build_mip_chain(std::move(level)));
  s.textures.push_back(t);
  Material m;
  m.name = "floor";
  m.diffuse = glm::vec3(1.0f);
  m.texture = 0;
  s.materials.push_back(m);
  Object o;
  o.name = "floor";
  o.type = ObjectType::Triangles;
  o.material = 1;
  const float h = float(kHalfWidth), zn = float(kNearZ), zf = float(kFarZ);
  o.mesh.positions = {{-h, 0, zn}, {h, 0, zn}, {h, 0, zf}, {-h, 0, zf}};
  for (const glm::vec3& p : o.mesh.positions)
    o.mesh.uvs.push_back(glm::vec2(float(p.x * kUvPerWorld), float(-p.z * kUvPerWorld)));
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(o);
  return s;
}

// The expected level at pixel position (px, py): the ray through it meets y = 0 at
// P = eye + t d, t = -eye.y / d.y (d the unnormalised direction of oracle::camera_ray);
// dP/dpx = t dd/dpx + d dt/dpx with dt/dpx = -t (dd/dpx).y / d.y; uv = (x, -z) / 4; the level is
// log2 of the longer of the two footprints in texels (the GL specification's rho).
// NaN where the ray misses the floor.
double expected_lod(const Camera& c, int width, int height, double px, double py) {
  const dvec3 eye(c.eye), forward = glm::normalize(dvec3(c.target) - eye);
  const dvec3 right = glm::normalize(glm::cross(forward, dvec3(c.up)));
  const dvec3 up = glm::cross(right, forward);
  const double tan_half = std::tan(double(c.fov_y_deg) * 3.14159265358979323846 / 360.0);
  const double aspect = double(width) / height;
  const double ndc_x = 2.0 * px / width - 1.0, ndc_y = 1.0 - 2.0 * py / height;
  const dvec3 d = forward + right * (ndc_x * tan_half * aspect) + up * (ndc_y * tan_half);
  const dvec3 dd_dx = right * (2.0 / width * tan_half * aspect);
  const dvec3 dd_dy = up * (-2.0 / height * tan_half);
  if (!(d.y < 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double t = -eye.y / d.y;
  const dvec3 P = eye + t * d;
  if (std::abs(P.x) > kHalfWidth || P.z > kNearZ || P.z < kFarZ)
    return std::numeric_limits<double>::quiet_NaN();
  auto footprint = [&](const dvec3& dd) {
    const dvec3 dP = t * dd + d * (-t * dd.y / d.y);
    return glm::length(dvec2(dP.x, -dP.z) * kUvPerWorld * double(kTexels));
  };
  return std::log2(std::max(footprint(dd_dx), footprint(dd_dy)));
}

// The floor's uv where the ray through pixel position (px, py) meets it (NaN off the floor).
dvec2 floor_uv(const Camera& c, int width, int height, double px, double py) {
  const oracle::Ray r = oracle::camera_ray(c, width, height, px, py);
  if (!(r.direction.y < 0.0)) return dvec2(std::numeric_limits<double>::quiet_NaN());
  const dvec3 P = r.origin + (-r.origin.y / r.direction.y) * r.direction;
  return dvec2(P.x, -P.z) * kUvPerWorld;
}

// The level a GL computing derivatives once per 2x2 quad (GL's quads: pairs of columns and of
// rows from the bottom) would give pixel (x, y): differences of the uvs of neighbouring pixel
// centres in the quad's row `ref_row` (0 its top, 1 its bottom) and its left column.
double quad_lod(const Camera& c, int width, int height, int x, int y, int ref_row) {
  const int x0 = x & ~1, y0 = y & ~1;  // image quads align with GL's: the height is even
  const double yr = y0 + ref_row + 0.5, xr = x0 + 0.5;
  const dvec2 dx = floor_uv(c, width, height, xr + 1.0, yr) - floor_uv(c, width, height, xr, yr);
  const dvec2 dy =
      floor_uv(c, width, height, xr, y0 + 0.5) - floor_uv(c, width, height, xr, y0 + 1.5);
  return std::log2(std::max(glm::length(dx), glm::length(dy)) * kTexels);
}

struct LodError {
  size_t checked = 0;
  double max_abs = 0.0, mean_abs = 0.0;
  double lod_min = 1e300, lod_max = -1e300;
};

// Whether pixel (x, y) and the points 1.5 pixels around its centre all see the floor: away from
// its edges, where the centre may fall either side.
bool well_inside(const Scene& s, int x, int y) {
  for (double dy : {-1.5, 0.0, 1.5})
    for (double dx : {-1.5, 0.0, 1.5})
      if (!std::isfinite(
              expected_lod(s.camera, s.image.width, s.image.height, x + 0.5 + dx, y + 0.5 + dy)))
        return false;
  return true;
}

// Every pixel well inside the floor.
LodError lod_error(const Scene& s, const FrameBuffers& fb) {
  LodError e;
  EXPECT_EQ(fb.lod.size(), fb.pixel_count());
  if (fb.lod.size() != fb.pixel_count()) return e;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x) {
      const size_t i = fb.index(x, y);
      if (!well_inside(s, x, y)) continue;
      const double want = expected_lod(s.camera, fb.width, fb.height, x + 0.5, y + 0.5);
      EXPECT_EQ(fb.object_id[i], 0u) << x << "," << y;
      const double err = std::abs(double(fb.lod[i]) - want);
      ++e.checked;
      e.mean_abs += err;
      e.max_abs = std::max(e.max_abs, std::isfinite(err) ? err : 1e300);
      e.lod_min = std::min(e.lod_min, want);
      e.lod_max = std::max(e.lod_max, want);
    }
  if (e.checked) e.mean_abs /= double(e.checked);
  return e;
}

RenderOutput render(Renderer& r, const Scene& s, RenderMode mode = RenderMode::Local) {
  RenderOptions options;
  options.mode = mode;
  Expected<RenderOutput> out = r.render(s, options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return out.ok() ? std::move(*out) : RenderOutput{};
}

// softraster's derivatives are exact closed forms of its plane equations in double; the level
// is rounded to float once (2^-24 relative: ~1e-6 levels at level 10). 1e-3 levels is float
// rounding of the uvs and positions (relative 1e-7, amplified where the floor is seen edge-on:
// the checked pixels stop 1.5 pixels short of the horizon).
TEST(TextureLod, SoftrasterMatchesTheClosedFormEverywhereOnTheGrazingPlane) {
  const Scene s = grazing_plane(320, 240);
  SoftRasterizer r;
  const RenderOutput out = render(r, s);
  const LodError e = lod_error(s, out.buffers);
  EXPECT_GT(e.checked, 20000u);
  EXPECT_LT(e.lod_min, 0.0);  // magnified at the bottom ...
  EXPECT_GT(e.lod_max, 6.0);  // ... to beyond the last level near the horizon
  EXPECT_LT(e.max_abs, 1e-3) << "mean " << e.mean_abs;
  RecordProperty("max_abs_lod_error", std::to_string(e.max_abs));
}

TEST(TextureLod, SoftrasterMatchesTheClosedFormOnTheRolledView) {
  const Scene s = grazing_plane(240, 320, /*rolled=*/true);
  SoftRasterizer r;
  const RenderOutput out = render(r, s);
  const LodError e = lod_error(s, out.buffers);
  EXPECT_GT(e.checked, 20000u);
  EXPECT_GT(e.lod_max, 6.0);
  EXPECT_LT(e.max_abs, 1e-3) << "mean " << e.mean_abs;
}

TEST(TextureLod, SoftrasterWritesNoLodWithoutTexturesAndNanOffTheTexture) {
  Scene s = grazing_plane(64, 48);
  SoftRasterizer r;
  RenderOutput out = render(r, s);
  ASSERT_EQ(out.buffers.lod.size(), out.buffers.pixel_count());
  size_t background = 0;
  for (size_t i = 0; i < out.buffers.pixel_count(); ++i)
    if (out.buffers.object_id[i] == kNoId) {
      ++background;
      EXPECT_TRUE(std::isnan(out.buffers.lod[i]));
    }
  EXPECT_GT(background, 0u);  // the sky
  s.materials[1].texture = -1;
  out = render(r, s);
  EXPECT_TRUE(out.buffers.lod.empty());
}

// GL: the level is the driver's (textureQueryLOD on llvmpipe), which takes derivatives once
// per 2x2 quad, as differences of the uvs of the quad's neighbouring pixels, and approximates
// log2. Against that model of a quad (computed here from the closed form's uvs) it agrees within
// 0.1 levels: a piecewise-linear log2 (the mantissa taken as its own logarithm) is off by up to
// 0.086 levels. Without the extension (ctest texture_lod_without_query_lod turns it off in Mesa)
// the shader's own formula on dFdx/dFdy, with an exact log2, agrees with the quad model within
// 0.01 levels (float differences of large uvs near the horizon). Against the exact per-pixel
// level the mean stays within the 0.1 levels; the largest differences are a quad's own
// change of level on the grazing rows.
TEST(TextureLod, GlMatchesTheClosedFormOfItsQuadsWithinItsLog2Approximation) {
  const Scene s = grazing_plane(320, 240);
  GlRasterizer r(GlBackend::OsMesa);
  const RenderOutput out = render(r, s);
  const LodError e = lod_error(s, out.buffers);
  EXPECT_GT(e.checked, 20000u);
  EXPECT_LT(e.mean_abs, 0.1);
  double quad_max = 0.0, quad_sum = 0.0;
  size_t quads = 0;
  for (int y = 0; y < s.image.height; ++y)
    for (int x = 0; x < s.image.width; ++x) {
      const size_t i = out.buffers.index(x, y);
      if (!well_inside(s, x, y)) continue;
      const double want = quad_lod(s.camera, s.image.width, s.image.height, x, y, 1);
      const double err = std::abs(double(out.buffers.lod[i]) - want);
      quad_max = std::max(quad_max, std::isfinite(err) ? err : 1e300);
      quad_sum += err;
      ++quads;
    }
  EXPECT_GT(quads, 20000u);
  const bool driver_lod = out.info.at("lod").find("textureQueryLOD") != std::string::npos;
  const char* overrides = std::getenv("MESA_EXTENSION_OVERRIDE");
  if (overrides && std::string(overrides).find("-GL_ARB_texture_query_lod") != std::string::npos) {
    EXPECT_FALSE(driver_lod);
  }
  EXPECT_LT(quad_max, driver_lod ? 0.1 : 0.01);
  std::cout << "GL (" << out.info.at("lod") << "): against the exact level max " << e.max_abs
            << " mean " << e.mean_abs << "; against its quads max " << quad_max << " mean "
            << quad_sum / double(std::max<size_t>(quads, 1)) << " levels\n";
}

// The hybrids' z-buffer pass: visibility mode with visibility_lod writes the very levels the
// shading pass does (NaN where they are NaN), and without it no lod buffer at all.
TEST(TextureLod, VisibilityModeWritesTheShadingPassesLodWhenAsked) {
  const Scene s = grazing_plane(160, 120);
  SoftRasterizer soft;
  GlRasterizer gl(GlBackend::OsMesa);
  for (Renderer* r : {static_cast<Renderer*>(&soft), static_cast<Renderer*>(&gl)}) {
    const RenderOutput shaded = render(*r, s);
    RenderOptions options;
    options.mode = RenderMode::Visibility;
    Expected<RenderOutput> plain = r->render(s, options);
    ASSERT_TRUE(plain.ok());
    EXPECT_TRUE(plain->buffers.lod.empty()) << r->name();
    options.visibility_lod = true;
    Expected<RenderOutput> ids = r->render(s, options);
    ASSERT_TRUE(ids.ok());
    ASSERT_EQ(ids->buffers.lod.size(), shaded.buffers.lod.size()) << r->name();
    size_t differ = 0, textured = 0;
    for (size_t i = 0; i < ids->buffers.lod.size(); ++i) {
      const float a = ids->buffers.lod[i], b = shaded.buffers.lod[i];
      textured += !std::isnan(a);
      differ += !(a == b || (std::isnan(a) && std::isnan(b)));
    }
    EXPECT_EQ(differ, 0u) << r->name();
    EXPECT_GT(textured, 5000u) << r->name();
  }
}

// The hybrids' z-buffer pass in softraster: with visibility_ids_only it writes the ids and
// levels of detail visibility mode writes without it, to the bit, and no other buffer. Its
// primitive ids are the target's, handed over: the same where a mesh was drawn (the only place a
// hybrid reads them), free elsewhere.
TEST(TextureLod, SoftrasterIdsOnlyWritesTheSameIdsAndLodAndNothingElse) {
  Expected<Scene> cornell = make_builtin_scene("cornell");
  ASSERT_TRUE(cornell.ok());
  size_t on_meshes = 0;  // pixels whose primitive ids were compared
  for (const Scene& s : {grazing_plane(160, 120), *cornell}) {
    SoftRasterizer soft;
    RenderOptions options;
    options.mode = RenderMode::Visibility;
    options.visibility_lod = true;
    Expected<RenderOutput> all = soft.render(s, options);
    options.visibility_ids_only = true;
    Expected<RenderOutput> first = soft.render(s, options);
    // The second ids-only frame: drawn into a target whose ids the first took.
    Expected<RenderOutput> ids = soft.render(s, options);
    ASSERT_TRUE(all.ok() && first.ok() && ids.ok());
    const FrameBuffers &a = all->buffers, &b = ids->buffers;
    EXPECT_TRUE(
        std::equal(a.object_id.begin(), a.object_id.end(), first->buffers.object_id.begin()));
    EXPECT_EQ(b.width, a.width);
    EXPECT_EQ(b.height, a.height);
    ASSERT_EQ(b.object_id.size(), a.pixel_count());
    EXPECT_TRUE(std::equal(a.object_id.begin(), a.object_id.end(), b.object_id.begin()));
    ASSERT_EQ(b.primitive_id.size(), a.pixel_count());
    for (size_t i = 0; i < a.pixel_count(); ++i) {
      if (a.object_id[i] == kNoId || s.objects[a.object_id[i]].type != ObjectType::Triangles)
        continue;
      ASSERT_EQ(b.primitive_id[i], a.primitive_id[i]) << i;
      ++on_meshes;
    }
    ASSERT_EQ(b.lod.size(), a.lod.size());
    for (size_t i = 0; i < a.lod.size(); ++i)
      ASSERT_TRUE(a.lod[i] == b.lod[i] || (std::isnan(a.lod[i]) && std::isnan(b.lod[i]))) << i;
    EXPECT_TRUE(b.depth.empty() && b.colour.empty() && b.normal.empty() && b.cost.empty());
    size_t covered = 0;
    for (uint32_t id : b.object_id) covered += id != kNoId;
    EXPECT_GT(covered, a.pixel_count() / 4);
  }
  EXPECT_GT(on_meshes, 160u * 120u / 4);
}

// A mesh whose texture coordinates or colours do not match its positions is bad input to both
// z-buffers, not a read past the end.
TEST(TextureLod, MismatchedUvsOrColoursAreBadInput) {
  for (bool colours : {false, true}) {
    Scene s = grazing_plane(32, 24);
    if (colours)
      s.objects[0].mesh.colours = {glm::vec3(1.0f)};
    else
      s.objects[0].mesh.uvs.pop_back();
    SoftRasterizer soft;
    GlRasterizer gl(GlBackend::OsMesa);
    for (Renderer* r : {static_cast<Renderer*>(&soft), static_cast<Renderer*>(&gl)}) {
      Expected<RenderOutput> out = r->render(s, RenderOptions{});
      ASSERT_FALSE(out.ok()) << r->name();
      EXPECT_EQ(out.error().kind, ErrorKind::BadInput);
      EXPECT_NE(out.error().message.find(colours ? "1 vertex colours for 4 positions"
                                                 : "3 texture coordinates for 4 positions"),
                std::string::npos)
          << out.error().message;
    }
  }
}

// A triangle leaning away from the camera, corners red, green and blue, lit by the ambient term
// alone (ambient 1, white diffuse): every pixel's colour is the vertex colour interpolated
// perspective-correctly, here the barycentrics of the ray-triangle intersection in double.
TEST(VertexColours, BothZBuffersInterpolatePerspectiveCorrectly) {
  Scene s;
  s.image.width = 160;
  s.image.height = 120;
  s.camera.eye = {0.0f, 0.5f, 2.0f};
  s.camera.target = {0.0f, 0.0f, -3.0f};
  s.camera.fov_y_deg = 50.0f;
  s.ambient = glm::vec3(1.0f);
  s.materials.push_back(Material{});
  Material white;
  white.diffuse = glm::vec3(1.0f);
  s.materials.push_back(white);
  Object o;
  o.type = ObjectType::Triangles;
  o.material = 1;
  o.mesh.positions = {{-2.0f, -1.0f, 0.5f}, {2.5f, -0.5f, -1.0f}, {0.0f, 2.0f, -12.0f}};
  o.mesh.colours = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  o.mesh.triangles = {{0, 1, 2}};
  s.objects.push_back(o);
  const dvec3 p0(o.mesh.positions[0]), e1 = dvec3(o.mesh.positions[1]) - p0,
                                       e2 = dvec3(o.mesh.positions[2]) - p0;
  // Barycentrics (1 - b1 - b2, b1, b2) where the ray through (px, py) meets the triangle, all
  // three above `margin` (away from its edges), else nothing.
  auto barycentrics = [&](double px, double py, double margin) -> std::optional<dvec3> {
    const oracle::Ray r = oracle::camera_ray(s.camera, s.image.width, s.image.height, px, py);
    const dvec3 q = glm::cross(r.direction, e2);
    const double det = glm::dot(e1, q);
    const dvec3 t = r.origin - p0;
    const double b1 = glm::dot(t, q) / det;
    const double b2 = glm::dot(r.direction, glm::cross(t, e1)) / det;
    const dvec3 b(1.0 - b1 - b2, b1, b2);
    if (b.x < margin || b.y < margin || b.z < margin) return std::nullopt;
    return b;
  };
  SoftRasterizer soft;
  GlRasterizer gl(GlBackend::OsMesa);
  for (Renderer* r : {static_cast<Renderer*>(&soft), static_cast<Renderer*>(&gl)}) {
    const RenderOutput out = render(*r, s);
    size_t checked = 0;
    double worst = 0.0;
    for (int y = 0; y < s.image.height; ++y)
      for (int x = 0; x < s.image.width; ++x) {
        const std::optional<dvec3> b = barycentrics(x + 0.5, y + 0.5, 0.02);
        if (!b) continue;
        ++checked;
        const glm::vec3 got = out.buffers.colour[out.buffers.index(x, y)];
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(got[c]) - (*b)[c]));
      }
    EXPECT_GT(checked, 2000u) << r->name();
    // Float barycentrics (relative 1e-6) times colours of 1.
    EXPECT_LT(worst, 1e-4) << r->name();
    EXPECT_TRUE(out.buffers.lod.empty()) << r->name();  // coloured, not textured
  }
}

// Textures change colours only: builtin:textured in both z-buffers has the same ids at every
// pixel, and the colours agree as far as their levels of detail do.
TEST(TextureLod, BuiltinTexturedSoftrasterAndGlSeeTheSameSurfaces) {
  Expected<Scene> scene = make_builtin_scene("textured");
  ASSERT_TRUE(scene.ok());
  scene->image.width = 320;
  scene->image.height = 240;
  SoftRasterizer soft;
  GlRasterizer gl(GlBackend::OsMesa);
  const RenderOutput a = render(soft, *scene), b = render(gl, *scene);
  ASSERT_EQ(a.buffers.pixel_count(), b.buffers.pixel_count());
  const ComparisonMetrics m = compare_buffers(a.buffers, b.buffers);
  std::cout << "builtin:textured softraster vs raster: id agreement " << m.visibility.id_agreement
            << ", colour PSNR " << m.colour.psnr_db << " dB\n";
  EXPECT_EQ(m.visibility.id_agreement, 1.0);
  EXPECT_GT(m.colour.psnr_db, 30.0);
  // The target for the two z-buffers' levels of detail: a mean within 0.1 levels.
  std::cout << "lod |soft - gl| mean " << m.lod.mean_abs << " p99 " << m.lod.p99_abs << " over "
            << m.lod.pixels << " pixels\n";
  EXPECT_GT(m.lod.pixels, 30000u);
  EXPECT_LT(m.lod.mean_abs, 0.1);
}

}  // namespace
}  // namespace rvr
