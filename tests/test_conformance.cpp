// Conformance: every renderer x every built-in scene, in local mode with spheres traced as the
// raster's tessellation, must agree with a renderer of the other loop order on what is seen.
// Every renderer of the table (rvr/renderers/registry.h) and every variant of one is a case.
// The reference is the table's first renderer of another loop order: raytrace for the
// z-buffers, raster for the tracers and for the hybrids (whose visibility is a z-buffer's and
// whose hits are the tracer's: both must hold).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <ostream>
#include <set>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/camera.h"
#include "rvr/core/check.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/surface_colour.h"
#include "rvr/core/tessellate.h"
#include "rvr/core/texture.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"

using namespace rvr;

namespace {

struct RendererCase {
  RendererChoice choice;  // "raster", "raster_egl", "raytrace_bvh2", ...
  std::string reference;  // the table's first renderer of another loop order
  double max_work;        // pixels x triangles; beyond it both images shrink (brute force is
                          // O(pixels x triangles), and the agreement rules hold at any size)
};

// Test names in ctest: "raster vs raytrace".
void PrintTo(const RendererCase& r, std::ostream* os) {
  *os << r.choice.name << " vs " << r.reference;
}

// Each pair once: "raytrace vs raster" would repeat "raster vs raytrace" (the metrics are
// symmetric but for which image is A), so a choice that is some earlier case's reference, with
// that case's renderer as its own reference, is left out.
std::vector<RendererCase> renderer_cases() {
  std::vector<RendererCase> cases;
  for (const RendererChoice& c : renderer_choices()) {
    std::string reference;
    for (const RendererInfo& r : renderers())
      if (reference.empty() && r.order != c.info->order) reference = r.name;
    const bool repeated = std::any_of(cases.begin(), cases.end(), [&](const RendererCase& k) {
      return k.choice.name == reference && k.reference == c.name;
    });
    if (repeated) continue;
    RendererConfig config;
    RenderOptions options;
    c.apply(config, options);
    // Every object for every ray: the image shrinks beyond 1.6e9 ray-triangle tests.
    cases.push_back({c, reference, options.accel == AccelKind::None ? 1.6e9 : 0.0});
  }
  return cases;
}

// Every built-in scene, sized for the test. `csg` is held apart: the z-buffers draw a CSG
// solid's leaves in passes of their own, counted by csg.* rather than triangles.submitted, so
// this suite's count of primitives drawn does not apply; both z-buffers' CSG is held to the
// tracer, with these bounds, by test_csg_zbuffer.
const char* kScenes[] = {"cornell",   "spheres",         "occluders:16",   "occluders_back:16",
                         "soup:2000", "tessphere:20000", "effects:5000",   "dof",
                         "discs",     "mirrors:16",      "mirror_balls:4", "glass",
                         "textured"};

TEST(ConformanceScenes, CoverEveryBuiltinSceneButCsg) {
  std::set<std::string> listed;
  for (const char* s : kScenes) listed.insert(std::string(s).substr(0, std::string(s).find(':')));
  for (const BuiltinSceneInfo& b : builtin_scenes()) {
    std::string name = b.name.substr(0, b.name.find(':'));
    if (name == "csg") continue;
    EXPECT_TRUE(listed.count(name)) << name << " is not in the conformance suite";
  }
}

// Thresholds (the contract, justified):
// - id agreement >= 0.999 and no mismatch away from an id boundary: the loop orders sample the
//   same pixel centres, so only ties on shared edges and silhouettes (a float rounding on
//   either side of an edge) may differ.
// - depth 1e-3 relative: GL interpolates eye-space z per fragment in float; the tracer
//   intersects in float; both are ~1e-6 apart except at grazing angles.
// - colour PSNR 40 dB: the same shading equation in GLSL and C++ on float inputs.
constexpr double kMinAgreement = 0.999;
constexpr double kMaxDepthRelError = 1e-3;
constexpr double kMinPsnr = 40.0;
// - colour per object, over the pixels away from every edge (colour_error_by_object), the
//   largest channel difference and its mean over the region:
//   - one sample per pixel: both shade the same surface point (the pixel centre's) with the
//     same equation in float; only how the point and normal are found differs (GL interpolates
//     them per fragment, the tracer from its own barycentrics), about 1e-5 apart. The steepest
//     term, Blinn-Phong with exponent 64, turns a normal error e into at most 64 e of colour
//     per unit of light: 1e-3 at a pixel. Rounding averages out over a region: 1e-5 mean, which
//     a wrong term on one pixel in 400 of a region (a 1/255 step) already crosses. Measured
//     on this suite: at most 8e-5 and 8e-7.
//   - several samples per pixel (dof has 16): every renderer takes the tracer's samples (the
//     z-buffers a pass per sample: the accumulation buffer, rvr/core/image_sample.h), so each
//     sample shades the same surface point on both sides and the averages keep the bounds of
//     one sample.
// - SSIM: see the test.
constexpr double kMaxRegionColourError = 1e-3, kMaxRegionMeanColourError = 1e-5;
constexpr double kSsimSlack = 1e-3;
constexpr int kSegments = 48;

// Renders with a table entry or variant, by name: its changes go over these settings.
RenderOutput render_with(const std::string& name, const Scene& scene, SphereMode spheres,
                         int segments, GlBackend gl = GlBackend::Default,
                         RenderMode mode = RenderMode::Local) {
  Expected<RendererChoice> choice = find_renderer_choice(name);
  EXPECT_TRUE(choice.ok()) << name;
  RendererConfig config{gl};
  RenderOptions options;
  options.mode = mode;
  options.spheres = spheres;
  options.sphere_segments = segments;
  // Textured scenes: the tracers' exact level of detail for primary rays (ray differentials), as
  // softraster's exact derivatives; GL has its own (see kMaxLodDifferenceGl).
  options.texture_lod = TextureLod::Differentials;
  choice->apply(config, options);
  auto renderer = choice->info->create(config);
  EXPECT_TRUE(renderer.ok());
  Expected<RenderOutput> out = renderer.value()->render(scene, options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return std::move(out).value();
}

// Whether a renderer's visible surfaces come from OpenGL's z-buffer (its own texture level of
// detail: llvmpipe's, per 2x2 quad).
bool uses_gl_zbuffer(const std::string& name) {
  return name.rfind("raster", 0) == 0 || name == "hybrid";
}

// Where the depth differs most among pixels whose ids agree, for the failure message.
std::string worst_depth(const FrameBuffers& a, const FrameBuffers& b) {
  double worst = 0;
  size_t at = 0;
  for (size_t i = 0; i < a.pixel_count(); ++i) {
    if (a.object_id[i] == kNoId || a.object_id[i] != b.object_id[i] ||
        a.primitive_id[i] != b.primitive_id[i])
      continue;
    double rel = std::abs(a.depth[i] - b.depth[i]) / std::max(a.depth[i], b.depth[i]);
    if (rel > worst) worst = rel, at = i;
  }
  return "worst at (" + std::to_string(at % a.width) + ", " + std::to_string(at / a.width) +
         "), object " + std::to_string(a.object_id[at]) + ": " + std::to_string(a.depth[at]) +
         " vs " + std::to_string(b.depth[at]);
}

// Primitives the scene holds as a renderer draws it with spheres as meshes, counted from the
// scene alone: a mesh's own triangles; a UV sphere of `segments` longitudes and segments / 2
// rings has two pole fans of `segments` triangles and segments / 2 - 2 bands of 2 * segments,
// segments * (segments - 2) in all; a square is two triangles for a z-buffer and one analytic
// primitive for a tracer (`square_primitives`); a disc is a fan of `segments` triangles.
size_t scene_primitives(const Scene& scene, int segments, size_t square_primitives) {
  size_t n = 0;
  for (const Object& o : scene.objects) {
    switch (o.type) {
      case ObjectType::Triangles:
        n += o.mesh.triangles.size();
        break;
      case ObjectType::Sphere:
        n += size_t(segments) * size_t(segments - 2);
        break;
      case ObjectType::Plane:
        n += square_primitives;
        break;
      case ObjectType::Disc:
        n += size_t(segments);
        break;
      case ObjectType::Csg:  // kScenes has none
        break;
    }
  }
  return n;
}

// What a renderer says it drew or traced, from its stats (docs/cli.md), and what the scene
// holds in that form: the z-buffers' triangles.submitted and the hybrids' z-buffer pass count
// triangles; the tracers' primitives are triangles plus analytic squares. -1 when none.
struct Drawn {
  double reported = -1;
  double expected = -1;
};
Drawn primitives_drawn(const RenderOutput& out, const Scene& scene) {
  auto stat = [&](const char* key) {
    auto it = out.stats.find(key);
    return it == out.stats.end() ? -1.0 : it->second;
  };
  const double zbuffer = stat("zbuffer.triangles.submitted") >= 0
                             ? stat("zbuffer.triangles.submitted")
                             : stat("triangles.submitted");
  if (zbuffer >= 0) return {zbuffer, double(scene_primitives(scene, kSegments, 2))};
  return {stat("primitives"), double(scene_primitives(scene, kSegments, 1))};
}

// Colour error of the pixels away from every edge, per object: pixels whose (object,
// primitive) id agrees and none of whose 3x3 neighbourhood lies on an id boundary in either
// image. There both renderers shade the same surface point with the same equation, so any
// difference is shading, not coverage.
struct RegionError {
  size_t pixels = 0;
  double sum = 0, max = 0;
  int max_x = 0, max_y = 0;
  double mean() const { return pixels ? sum / double(pixels) : 0.0; }
};

std::map<uint32_t, RegionError> colour_error_by_object(const FrameBuffers& a,
                                                       const FrameBuffers& b) {
  std::vector<bool> edge = id_boundaries(a);
  const std::vector<bool> edge_b = id_boundaries(b);
  for (size_t i = 0; i < edge.size(); ++i) edge[i] = edge[i] || edge_b[i];
  std::map<uint32_t, RegionError> regions;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const size_t i = a.index(x, y);
      if (a.object_id[i] == kNoId || a.object_id[i] != b.object_id[i] ||
          a.primitive_id[i] != b.primitive_id[i])
        continue;
      bool near_edge = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < a.width && yy < a.height && edge[a.index(xx, yy)])
            near_edge = true;
        }
      if (near_edge) continue;
      double d = 0;
      for (int c = 0; c < 3; ++c)
        d = std::max(d, double(std::abs(a.colour[i][c] - b.colour[i][c])));
      if (std::isnan(d)) d = 1.0;
      RegionError& r = regions[a.object_id[i]];
      ++r.pixels;
      r.sum += d;
      if (d > r.max) r.max = d, r.max_x = x, r.max_y = y;
    }
  return regions;
}

// A textured object's pixels: a texture is sampled with one rule everywhere, so its colour
// differs between two renderers only through where (uv) and at which level of detail it is
// sampled.
// - Level of detail: the tracers' ray differentials and softraster's plane-equation
//   derivatives are both exact for primary hits, equal to the closed form within float
//   rounding (test_texture_lod, test_tracer_texture: under 1e-3 level); GL's is llvmpipe's,
//   per 2x2 quad with an approximate log2: up to 0.52 levels from the closed form on grazing
//   rows (test_texture_lod), so 0.6.
// - Colour, exact pairs only: the uv of a pixel centre differs by float rounding of the
//   perspective division, about 1e-6 relative of uv * texture size (32 repeats of 128 texels:
//   4e-3 texel); at a checker edge of level 0 bilinear filtering turns a texel of position into
//   the full contrast (0.8), so 3e-3 at a pixel; rounding averages out over the region: 1e-4
//   mean. With GL the level alone may differ by 0.6, which blends in up to 0.6 of the next
//   level's texel: the whole image's PSNR is the colour check there.
constexpr double kMaxLodDifferenceExact = 1e-3, kMaxLodDifferenceGl = 0.6;
constexpr double kMaxTexturedColourError = 3e-3, kMaxTexturedMeanColourError = 1e-4;

void check_textured_region(const FrameBuffers& a, const FrameBuffers& b, uint32_t object, bool gl,
                           const RegionError& region, const std::string& where) {
  ASSERT_FALSE(a.lod.empty());
  ASSERT_FALSE(b.lod.empty());
  size_t compared = 0;
  double worst = 0;
  for (size_t i = 0; i < a.pixel_count(); ++i) {
    if (a.object_id[i] != object || b.object_id[i] != object) continue;
    if (a.primitive_id[i] != b.primitive_id[i]) continue;
    ASSERT_FALSE(std::isnan(a.lod[i]) || std::isnan(b.lod[i])) << where << ": pixel " << i;
    worst = std::max(worst, double(std::fabs(a.lod[i] - b.lod[i])));
    ++compared;
  }
  EXPECT_GT(compared, 0u) << where;
  EXPECT_LE(worst, gl ? kMaxLodDifferenceGl : kMaxLodDifferenceExact) << where;
  if (gl) return;
  EXPECT_LE(region.max, kMaxTexturedColourError) << where;
  EXPECT_LE(region.mean(), kMaxTexturedMeanColourError) << where;
}

class Conformance : public ::testing::TestWithParam<std::tuple<RendererCase, const char*>> {};

}  // namespace

TEST_P(Conformance, AgreesWithTheOtherLoopOrder) {
  const auto& [r, scene_name] = GetParam();
  Expected<Scene> scene = make_builtin_scene(scene_name);
  ASSERT_TRUE(scene.ok());
  // Triangles as the tracer sees them with --spheres mesh.
  size_t triangles = scene->triangle_count();
  for (const Object& o : scene->objects)
    if (o.type == ObjectType::Sphere) triangles += size_t(kSegments) * (kSegments - 2);
  double work = double(triangles) * scene->image.width * scene->image.height;
  if (r.max_work > 0 && work * scene->image.samples_per_pixel > r.max_work) {
    // Supersampling is covered by the other tracers; brute force checks visibility.
    scene->image.samples_per_pixel = 1;
  }
  const bool shrunk = r.max_work > 0 && work > r.max_work;
  if (shrunk) {
    // Keep the aspect ratio; 64 px wide at least so silhouettes still cover many pixels.
    double scale = std::max(std::sqrt(r.max_work / work), 64.0 / scene->image.width);
    scene->image.width = std::max(1, int(scene->image.width * scale));
    scene->image.height = std::max(1, int(scene->image.height * scale));
  }

  // The raster pins OSMesa unless its variant asks for EGL, so that raster and raster_egl test
  // both back ends (the default falls back to EGL when OSMesa is missing).
  RenderOutput a =
      render_with(r.choice.name, *scene, SphereMode::Mesh, kSegments, GlBackend::OsMesa);
  RenderOutput b = render_with(r.reference, *scene, SphereMode::Mesh, kSegments);
  ComparisonMetrics m = compare_buffers(a.buffers, b.buffers);

  // Something must be seen, or agreement means nothing.
  size_t covered = 0;
  for (uint32_t id : a.buffers.object_id) covered += id != kNoId;
  EXPECT_GT(covered, a.buffers.pixel_count() / 10);

  EXPECT_GE(m.visibility.id_agreement, kMinAgreement)
      << m.visibility.mismatched_pixels << " mismatched pixels";
  EXPECT_EQ(m.visibility.classes.not_edge(), 0u);
  EXPECT_LE(m.depth.max_rel_error, kMaxDepthRelError) << worst_depth(a.buffers, b.buffers);
  EXPECT_EQ(m.depth.outliers_elsewhere, 0u) << worst_depth(a.buffers, b.buffers);
  EXPECT_GE(m.colour.psnr_db, kMinPsnr);

  // SSIM: a window without a mismatched pixel sees the same structure in both images, and
  // its luminance term differs from 1 by about (colour error)^2 / (2 mean^2): below 1e-3
  // (kSsimSlack) for the region errors allowed below (mean 1e-3 at most) on surfaces brighter
  // than 0.05. A window holding a mismatch may drop to anything: 11x11 windows, so at most
  // 121 windows per mismatched pixel.
  const double windows_with_a_mismatch =
      std::min(1.0, 121.0 * double(m.visibility.mismatched_pixels) / double(m.visibility.pixels));
  EXPECT_GE(m.colour.ssim, 1.0 - windows_with_a_mismatch - kSsimSlack)
      << m.visibility.mismatched_pixels << " mismatched pixels";

  // Colour per object, away from edges: the whole-image PSNR lets a wrong region of 1% of the
  // image pass; these do not.
  const auto regions = colour_error_by_object(a.buffers, b.buffers);
  // Only a dense mesh shrunk for the brute-force tracer (64 px wide, every pixel beside a
  // triangle edge) may leave no region; then the whole image's PSNR is the colour check.
  if (!shrunk) {
    EXPECT_FALSE(regions.empty()) << "no object has a pixel away from every edge: nothing checked";
  }
  const bool gl = uses_gl_zbuffer(r.choice.name) || uses_gl_zbuffer(r.reference);
  for (const auto& [object, region] : regions) {
    const std::string where = "object " + std::to_string(object) + " (" +
                              scene->objects[object].name + "), worst at (" +
                              std::to_string(region.max_x) + ", " + std::to_string(region.max_y) +
                              ") of " + std::to_string(region.pixels) + " pixels";
    if (textured(*scene, scene->objects[object])) {
      check_textured_region(a.buffers, b.buffers, object, gl, region, where);
      continue;
    }
    EXPECT_LE(region.max, kMaxRegionColourError) << where;
    EXPECT_LE(region.mean(), kMaxRegionMeanColourError) << where;
  }

  // Every triangle of the scene drawn (or traced): a dropped one hides among edge ties in a
  // dense mesh, where every pixel is near an edge.
  const Drawn drawn_a = primitives_drawn(a, *scene), drawn_b = primitives_drawn(b, *scene);
  EXPECT_EQ(drawn_a.reported, drawn_a.expected) << r.choice.name;
  EXPECT_EQ(drawn_b.reported, drawn_b.expected) << r.reference;
  RecordProperty("id_agreement", std::to_string(m.visibility.id_agreement));
  RecordProperty("psnr_db", std::to_string(m.colour.psnr_db));
  RecordProperty("ssim", std::to_string(m.colour.ssim));
}

INSTANTIATE_TEST_SUITE_P(EveryRendererEveryScene, Conformance,
                         ::testing::Combine(::testing::ValuesIn(renderer_cases()),
                                            ::testing::ValuesIn(kScenes)),
                         [](const ::testing::TestParamInfo<Conformance::ParamType>& info) {
                           std::string s =
                               std::get<0>(info.param).choice.name + "_" + std::get<1>(info.param);
                           for (char& c : s)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return s;
                         });

// The two GL back ends (OSMesa and EGL surfaceless) differ only in how the context is made;
// both run the same Mesa release's llvmpipe, which is deterministic, so every buffer must be
// bit-identical. Full mode, so shadow maps (layered depth textures, geometry shader) and
// multisampling are covered too, not only the visibility pass.
class GlBackends : public ::testing::TestWithParam<const char*> {};

TEST_P(GlBackends, OsMesaAndEglRenderIdenticalBuffers) {
  Expected<Scene> scene = make_builtin_scene(GetParam());
  ASSERT_TRUE(scene.ok());
  RenderOutput osmesa = render_with("raster", *scene, SphereMode::Mesh, kSegments,
                                    GlBackend::OsMesa, RenderMode::Full);
  RenderOutput egl =
      render_with("raster", *scene, SphereMode::Mesh, kSegments, GlBackend::Egl, RenderMode::Full);
  const FrameBuffers& a = osmesa.buffers;
  const FrameBuffers& b = egl.buffers;
  ASSERT_EQ(a.pixel_count(), b.pixel_count());
  size_t differing = 0;
  for (size_t i = 0; i < a.pixel_count(); ++i) {
    bool same = a.object_id[i] == b.object_id[i] && a.primitive_id[i] == b.primitive_id[i] &&
                std::memcmp(&a.depth[i], &b.depth[i], sizeof(float)) == 0 &&
                std::memcmp(&a.colour[i], &b.colour[i], sizeof(a.colour[i])) == 0 &&
                std::memcmp(&a.normal[i], &b.normal[i], sizeof(a.normal[i])) == 0;
    differing += !same;
  }
  EXPECT_EQ(differing, 0u) << "of " << a.pixel_count() << " pixels";
  EXPECT_EQ(osmesa.warnings, egl.warnings);
  EXPECT_GT(osmesa.stats.at("fragments.generated"), 0.0);
  EXPECT_EQ(osmesa.stats.at("fragments.generated"), egl.stats.at("fragments.generated"));
  EXPECT_EQ(osmesa.stats.at("fragments.passed"), egl.stats.at("fragments.passed"));
}

INSTANTIATE_TEST_SUITE_P(EveryScene, GlBackends, ::testing::ValuesIn(kScenes),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string s = info.param;
                           for (char& c : s)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return s;
                         });

// With analytic spheres the tracer sees the true silhouette and the z-buffer its polygon:
// mismatches must lie on sphere silhouettes, within the tessellation's projected error, and
// shrink as the segment count grows.
TEST(AnalyticSpheres, MismatchesStayOnSilhouettesAndShrinkWithSegments) {
  Expected<Scene> scene = make_builtin_scene("spheres");
  ASSERT_TRUE(scene.ok());
  const Scene& s = *scene;
  CameraFrame frame = make_camera_frame(s.camera, s.image.width, s.image.height);
  float focal_px = 0.5f * float(s.image.height) / frame.tan_half_fov_y;

  size_t previous = SIZE_MAX;
  for (int segments : {12, 24, 48, 96}) {
    RenderOutput traced = render_with("raytrace", s, SphereMode::Analytic, segments);
    RenderOutput raster = render_with("raster", s, SphereMode::Analytic, segments);
    ComparisonMetrics m = compare_buffers(traced.buffers, raster.buffers);
    size_t mismatched = m.visibility.mismatched_pixels;

    // Largest gap between a sphere and its inscribed polygon (a quad spanning 2*pi/segments
    // in both directions: its centre lies deepest), projected at the nearest sphere.
    float worst_px = 0.0f;
    for (const Object& o : s.objects) {
      if (o.type != ObjectType::Sphere) continue;
      float angle = 3.14159265f * std::sqrt(2.0f) / float(segments);
      float gap = o.sphere.radius * (1.0f - std::cos(angle));
      float distance = glm::length(o.sphere.center - s.camera.eye) - o.sphere.radius;
      worst_px = std::max(worst_px, focal_px * gap / distance);
    }
    int reach = int(std::ceil(worst_px)) + 1;

    std::vector<bool> edge = id_boundaries(traced.buffers);
    const FrameBuffers& fa = traced.buffers;
    const FrameBuffers& fb = raster.buffers;
    size_t far_from_silhouette = 0;
    for (int y = 0; y < fa.height; ++y) {
      for (int x = 0; x < fa.width; ++x) {
        size_t i = fa.index(x, y);
        if (fa.object_id[i] == fb.object_id[i] && fa.primitive_id[i] == fb.primitive_id[i])
          continue;
        bool near_edge = false;
        for (int dy = -reach; dy <= reach && !near_edge; ++dy)
          for (int dx = -reach; dx <= reach && !near_edge; ++dx) {
            int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < fa.width && yy < fa.height && edge[fa.index(xx, yy)])
              near_edge = true;
          }
        far_from_silhouette += !near_edge;
      }
    }
    EXPECT_EQ(far_from_silhouette, 0u) << segments << " segments, reach " << reach << " px";
    EXPECT_LT(mismatched, previous) << segments << " segments";
    previous = mismatched;
  }
}

namespace {

// The facet of `mesh` the ray through the centre of pixel (x, y) meets first, found in double
// precision (Moller-Trumbore over every facet), or kNoId.
uint32_t exact_facet(const Scene& scene, const TriangleMesh& mesh, int x, int y) {
  const CameraFrame frame = make_camera_frame(scene.camera, scene.image.width, scene.image.height);
  const glm::dvec3 eye(scene.camera.eye);
  const glm::dvec3 d(camera_ray_direction(frame, float(x) + 0.5f, float(y) + 0.5f));
  uint32_t best = kNoId;
  double best_t = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const glm::uvec3 t = mesh.triangles[i];
    const glm::dvec3 a(mesh.positions[t.x]), e1 = glm::dvec3(mesh.positions[t.y]) - a,
                                             e2 = glm::dvec3(mesh.positions[t.z]) - a;
    const glm::dvec3 p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (det == 0.0) continue;
    const glm::dvec3 s = eye - a, q = glm::cross(s, e1);
    const double u = glm::dot(s, p) / det, v = glm::dot(d, q) / det, h = glm::dot(e2, q) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && h > 0 && h < best_t) best = uint32_t(i), best_t = h;
  }
  return best;
}

}  // namespace

// Tessellated spheres (--spheres mesh) are the same triangles for every renderer, so their
// facets are named like a mesh's. At the two grazing pixels below the pixel centre lies inside a
// sliver facet of about 0.006 px^2 on screen; GL snaps vertices to 1/256 pixel, the sliver
// moves off the centre and its neighbour, whose edge passes within 1/256 pixel of the centre,
// takes the pixel. With one primitive id per sphere that showed as a depth outlier of 1.5e-3
// on "the same primitive"; with facet ids it is a named edge tie.
TEST(TessellatedSpheres, GrazingFacetSwapsAreEdgeTiesNotDepthErrors) {
  Expected<Scene> scene = make_builtin_scene("spheres");
  ASSERT_TRUE(scene.ok());
  const int segments = 64;  // the command line's default
  RenderOutput gl = render_with("raster", *scene, SphereMode::Mesh, segments, GlBackend::OsMesa);
  RenderOutput rt = render_with("raytrace", *scene, SphereMode::Mesh, segments);
  MismatchContext context;
  context.scene = &*scene;
  context.store_a = DepthStore::Window32FReversed;
  context.sphere_segments = segments;
  ComparisonMetrics m = compare_buffers(gl.buffers, rt.buffers, context);
  EXPECT_EQ(m.depth.outliers, 0u) << worst_depth(gl.buffers, rt.buffers);
  EXPECT_EQ(m.visibility.classes.not_edge(), 0u);
  EXPECT_GT(m.visibility.classes.edge, 0u);  // facets now disagree on ties, as meshes do

  const std::vector<MismatchClass> classes = classify_mismatches(gl.buffers, rt.buffers, context);
  for (auto [x, y] : {std::pair{197, 259}, std::pair{442, 259}}) {
    const size_t i = gl.buffers.index(x, y);
    const uint32_t object = rt.buffers.object_id[i];
    ASSERT_NE(object, kNoId);
    ASSERT_EQ(scene->objects[object].type, ObjectType::Sphere);
    const TriangleMesh facets = tessellate_sphere(scene->objects[object].sphere, segments);
    EXPECT_EQ(rt.buffers.primitive_id[i], exact_facet(*scene, facets, x, y)) << x << "," << y;
    EXPECT_EQ(gl.buffers.object_id[i], object);
    EXPECT_NE(gl.buffers.primitive_id[i], rt.buffers.primitive_id[i]) << x << "," << y;
    EXPECT_EQ(classes[i], MismatchClass::Edge) << x << "," << y;
  }
}
