// Shadow maps (raster) against shadow rays (tracer) on the Cornell box: whether each pixel is
// lit, partly lit or shadowed by the area light must agree almost everywhere.
#include <gtest/gtest.h>

#include <cstdio>
#include <glm/glm.hpp>
#include <vector>

#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raster/soft_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/shared/scene_loader.h"

namespace rvr {
namespace {

float luminance(const glm::vec3& c) {
  return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}

enum class LightState { Lit, Partial, Shadowed };

// The share of the direct light that reaches the pixel, full / local, with what needs no light
// (emission + ambient * diffuse, known from the material) taken off both.
LightState classify(float full, float local, float base) {
  float ratio = (full - base) / (local - base);
  if (ratio > 0.9f) return LightState::Lit;
  if (ratio < 0.1f) return LightState::Shadowed;
  return LightState::Partial;
}

Expected<RenderOutput> render(Renderer& r, const Scene& s, RenderMode mode) {
  RenderOptions options;
  options.mode = mode;
  options.spheres = SphereMode::Mesh;  // the tracer intersects the raster's tessellation
  return r.render(s, options);
}

// Lit / partly lit / shadowed per pixel, from a full and a local render of one renderer.
struct Classified {
  std::vector<LightState> state;  // per pixel
  std::vector<bool> valid;        // covered and receiving direct light without shadows
};

Classified classify_renders(const Scene& s, const FrameBuffers& full, const FrameBuffers& local) {
  Classified c;
  c.state.resize(full.pixel_count(), LightState::Lit);
  c.valid.resize(full.pixel_count(), false);
  for (size_t i = 0; i < full.pixel_count(); ++i) {
    uint32_t id = full.object_id[i];
    if (id == kNoId) continue;
    const Material& m = s.materials[s.objects[id].material];
    float base = luminance(m.emission + s.ambient * m.diffuse);
    // No direct light even without shadows (facing away): nothing to classify.
    if (luminance(local.color[i]) - base < 1e-4f) continue;
    c.state[i] = classify(luminance(full.color[i]), luminance(local.color[i]), base);
    c.valid[i] = true;
  }
  return c;
}

struct Agreement {
  size_t compared = 0, agree = 0, shadowed = 0;
  double percent() const { return compared ? 100.0 * double(agree) / double(compared) : 0.0; }
};

// Pixels where both see the same object and both classify.
Agreement agreement(const FrameBuffers& a_ids, const Classified& a, const FrameBuffers& b_ids,
                    const Classified& b) {
  Agreement r;
  for (size_t i = 0; i < a.state.size(); ++i) {
    if (!a.valid[i] || !b.valid[i] || a_ids.object_id[i] != b_ids.object_id[i]) continue;
    ++r.compared;
    r.agree += a.state[i] == b.state[i] ? 1 : 0;
    r.shadowed += b.state[i] != LightState::Lit ? 1 : 0;
  }
  return r;
}

// The Cornell box with mirror and glass taken away (the tracer's would change colours the
// rasterizers cannot), so full mode is local shading times visibility in every renderer; area
// light samples at the stratum centres in all.
Scene cornell_for_shadows() {
  auto loaded = make_builtin_scene("cornell");
  EXPECT_TRUE(loaded.ok()) << loaded.error().message;
  Scene s = loaded.value();
  for (Material& m : s.materials) m.mirror = m.transparency = 0.0f;
  s.image.samples_per_pixel = 1;
  return s;
}

struct Classification {
  FrameBuffers full;
  Classified classes;
};

Classification classify_renderer(Renderer& r, const Scene& s) {
  auto full = render(r, s, RenderMode::Full);
  auto local = render(r, s, RenderMode::Local);
  EXPECT_TRUE(full.ok() && local.ok());
  Classification c;
  c.classes = classify_renders(s, full->buffers, local->buffers);
  c.full = std::move(full->buffers);
  return c;
}

TEST(ShadowAgreement, ShadowMapsVsShadowRaysOnCornellAgreeOnAtLeast98Percent) {
  Scene s = cornell_for_shadows();
  GlRasterizer raster;
  RayTracer tracer;
  Classification gl = classify_renderer(raster, s);
  Classification rays = classify_renderer(tracer, s);
  Agreement a = agreement(gl.full, gl.classes, rays.full, rays.classes);
  std::printf(
      "shadow agreement on builtin:cornell %dx%d: %.2f%% of %zu pixels (%zu not fully "
      "lit by the tracer)\n",
      gl.full.width, gl.full.height, a.percent(), a.compared, a.shadowed);
  EXPECT_GT(a.compared, gl.full.pixel_count() / 2);
  EXPECT_GT(a.shadowed, a.compared / 50);  // the test means something: there are shadows
  EXPECT_GE(a.percent(), 98.0);
}

// softraster's shadow cubes, drawn by its own z-buffer, against GL's (the same maps, bias and
// lookup: >= 99.5% of pixels classify alike; what differs is rounding on shadow edges, where
// the two z-buffers' maps differ by a texel) and against the tracer's shadow rays (at least as
// well as GL's maps agree with them, less 0.2 points of such edge pixels). Also with PCF.
TEST(ShadowAgreement, SoftrasterShadowMapsAgreeWithGlAndWithShadowRays) {
  Scene s = cornell_for_shadows();
  GlRasterizer raster;
  RayTracer tracer;
  SoftRasterizer soft;
  Classification gl = classify_renderer(raster, s);
  Classification rays = classify_renderer(tracer, s);
  Classification ours = classify_renderer(soft, s);
  Agreement with_gl = agreement(ours.full, ours.classes, gl.full, gl.classes);
  Agreement with_rays = agreement(ours.full, ours.classes, rays.full, rays.classes);
  Agreement gl_rays = agreement(gl.full, gl.classes, rays.full, rays.classes);
  std::printf(
      "softraster shadow maps vs GL's: %.3f%% of %zu pixels; vs shadow rays: %.3f%% "
      "(GL's vs shadow rays: %.3f%%)\n",
      with_gl.percent(), with_gl.compared, with_rays.percent(), gl_rays.percent());
  EXPECT_GT(with_gl.compared, ours.full.pixel_count() / 2);
  EXPECT_GT(with_gl.shadowed, with_gl.compared / 50);
  EXPECT_GE(with_gl.percent(), 99.5);
  EXPECT_GE(with_rays.percent(), gl_rays.percent() - 0.2);
}

TEST(ShadowAgreement, SoftrasterPcfAgreesWithGlPcf) {
  Scene s = cornell_for_shadows();
  RenderOptions options;
  options.spheres = SphereMode::Mesh;
  options.shadow_pcf = true;
  GlRasterizer raster;
  SoftRasterizer soft;
  auto classify_with = [&](Renderer& r) {
    options.mode = RenderMode::Full;
    auto full = r.render(s, options);
    options.mode = RenderMode::Local;
    auto local = r.render(s, options);
    EXPECT_TRUE(full.ok() && local.ok());
    Classification c;
    c.classes = classify_renders(s, full->buffers, local->buffers);
    c.full = std::move(full->buffers);
    return c;
  };
  Classification gl = classify_with(raster);
  Classification ours = classify_with(soft);
  Agreement a = agreement(ours.full, ours.classes, gl.full, gl.classes);
  std::printf("softraster PCF vs GL PCF: %.3f%% of %zu pixels\n", a.percent(), a.compared);
  EXPECT_GE(a.percent(), 99.5);
}

}  // namespace
}  // namespace rvr
