// Shadow maps (raster) against shadow rays (tracer) on the Cornell box: whether each pixel is
// lit, partly lit or shadowed by the area light must agree almost everywhere.
#include <gtest/gtest.h>

#include <cstdio>
#include <glm/glm.hpp>

#include "rvr/raster/gl_rasterizer.h"
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

TEST(ShadowAgreement, ShadowMapsVsShadowRaysOnCornellAgreeOnAtLeast98Percent) {
  auto loaded = make_builtin_scene("cornell");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  Scene s = loaded.value();
  // The tracer's mirror and glass would change colours the raster cannot: take them away, so
  // full mode is local shading times visibility in both renderers.
  for (Material& m : s.materials) m.mirror = m.transparency = 0.0f;
  s.image.samples_per_pixel = 1;  // area-light samples at the stratum centres in both

  GlRasterizer raster;
  RayTracer tracer;
  auto raster_full = render(raster, s, RenderMode::Full);
  auto raster_local = render(raster, s, RenderMode::Local);
  auto trace_full = render(tracer, s, RenderMode::Full);
  auto trace_local = render(tracer, s, RenderMode::Local);
  for (auto* out : {&raster_full, &raster_local, &trace_full, &trace_local})
    ASSERT_TRUE(out->ok()) << out->error().message;

  const FrameBuffers& rf = raster_full->buffers;
  const FrameBuffers& rl = raster_local->buffers;
  const FrameBuffers& tf = trace_full->buffers;
  const FrameBuffers& tl = trace_local->buffers;
  size_t compared = 0, agree = 0, shadowed = 0;
  for (size_t i = 0; i < rf.pixel_count(); ++i) {
    uint32_t id = rf.object_id[i];
    if (id == kNoId || id != tf.object_id[i]) continue;
    const Material& m = s.materials[s.objects[id].material];
    float base = luminance(m.emission + s.ambient * m.diffuse);
    // No direct light even without shadows (facing away): nothing to classify.
    if (luminance(rl.color[i]) - base < 1e-4f || luminance(tl.color[i]) - base < 1e-4f) continue;
    LightState a = classify(luminance(rf.color[i]), luminance(rl.color[i]), base);
    LightState b = classify(luminance(tf.color[i]), luminance(tl.color[i]), base);
    ++compared;
    agree += a == b ? 1 : 0;
    shadowed += b != LightState::Lit ? 1 : 0;
  }
  const double percent = compared ? 100.0 * double(agree) / double(compared) : 0.0;
  std::printf(
      "shadow agreement on builtin:cornell %dx%d: %.2f%% of %zu pixels (%zu not fully "
      "lit by the tracer)\n",
      rf.width, rf.height, percent, compared, shadowed);
  EXPECT_GT(compared, rf.pixel_count() / 2);
  EXPECT_GT(shadowed, compared / 50);  // the test means something: there are shadows
  EXPECT_GE(percent, 98.0);
}

}  // namespace
}  // namespace rvr
