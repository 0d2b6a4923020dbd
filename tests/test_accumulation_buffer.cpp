// The z-buffers' accumulation buffer (raster/src/accumulation_buffer.h): supersampling and depth
// of field as one pass per sample of the tracer's own sample set, so that both loop orders
// average the same rays.
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/camera.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/renderers/registry.h"
#include "same_bytes.h"
#include "table_render.h"

namespace rvr {
namespace {

// Primary visibility's id tolerance (test_conformance): ids agree but on edge ties. Colour: the
// hybrid's full-mode bar (test_hybrid), 50 dB, which a shading error of 1/255 everywhere (48 dB)
// fails. Each pass sees what the tracer's sample sees, so the two differ per sample only on edge
// ties and by shadow maps against shadow rays, and the average of 16 samples dilutes the ties:
// measured 53.8 dB for both z-buffers at 128x96 (43.6 dB with one sample, where a tie is a whole
// pixel). Passes through the pinhole instead of the lens points measured 39.7 dB.
constexpr double kMinAgreement = 0.999;
constexpr double kMinPsnr = 50.0;

using test::small_builtin_scene;

RenderOutput render(const std::string& renderer, const Scene& scene, RenderMode mode,
                    int threads = 0, Supersampling supersampling = Supersampling::Accumulation) {
  RenderOptions options;
  options.mode = mode;
  options.threads = threads;
  options.supersampling = supersampling;
  return test::table_render(renderer, scene, options);
}

}  // namespace

// A sample's view matrix puts its eye, the point its pass shades towards, at the origin: the
// eye the z-buffer shades from is the one it draws from, and the tracer's lens point (the eye
// moved along the camera's right and up axes).
TEST(AccumulationBuffer, ASamplesEyeIsWhereItsViewLooksFrom) {
  const Scene scene = small_builtin_scene("dof");
  const CameraFrame frame = make_camera_frame(scene.camera, 128, 96);
  for (int k = 0; k < scene.image.samples_per_pixel; ++k) {
    const ImageSample s =
        image_sample(scene.camera, 7, k, scene.image.samples_per_pixel, /*thin_lens=*/true);
    ASSERT_NE(s.lens_x, 0.0f);
    const glm::vec3 eye = sample_eye(scene.camera, s);
    const glm::vec4 in_view = sample_view_matrix(scene.camera, s) * glm::vec4(eye, 1.0f);
    EXPECT_NEAR(glm::length(glm::vec3(in_view)), 0.0f, 1e-5f) << k;
    const glm::vec3 lens = frame.eye + s.lens_x * frame.right + s.lens_y * frame.up;
    EXPECT_NEAR(glm::length(eye - lens), 0.0f, 1e-6f) << k;
  }
}

// Depth of field: every z-buffer draws the tracer's lens samples, one pass each, so its image is
// the tracer's up to rasterization (and, in full mode, shadow maps against shadow rays).
TEST(AccumulationBuffer, DepthOfFieldAgreesWithTheTracer) {
  const Scene scene = small_builtin_scene("dof");
  const int spp = scene.image.samples_per_pixel;
  ASSERT_GT(spp, 1);
  ASSERT_GT(scene.camera.aperture_radius, 0.0f);
  const RenderOutput traced = render("raytrace", scene, RenderMode::Full);
  Scene pinhole = scene;
  pinhole.image.samples_per_pixel = 1;
  for (const char* zbuffer : {"raster", "softraster"}) {
    const RenderOutput out = render(zbuffer, scene, RenderMode::Full);
    ASSERT_EQ(out.buffers.pixel_count(), traced.buffers.pixel_count()) << zbuffer;
    EXPECT_EQ(out.stats.at("zbuffer.accumulation_passes"), double(spp)) << zbuffer;
    for (const std::string& w : out.warnings)
      EXPECT_EQ(w.find("depth of field"), std::string::npos) << zbuffer << ": " << w;
    const ComparisonMetrics m = compare_buffers(out.buffers, traced.buffers);
    EXPECT_GE(m.visibility.id_agreement, kMinAgreement) << zbuffer;
    EXPECT_EQ(m.visibility.classes.not_edge(), 0u) << zbuffer;
    EXPECT_GE(m.colour.psnr_db, kMinPsnr) << zbuffer;
    RecordProperty(std::string(zbuffer) + "_psnr_db", std::to_string(m.colour.psnr_db));

    // The AOVs are the centre pass's: those of one sample per pixel, to the byte.
    const RenderOutput centre = render(zbuffer, pinhole, RenderMode::Full);
    EXPECT_EQ(out.buffers.object_id, centre.buffers.object_id) << zbuffer;
    EXPECT_TRUE(test::same_bytes(out.buffers.depth, centre.buffers.depth)) << zbuffer;
    EXPECT_TRUE(test::same_bytes(out.buffers.normal, centre.buffers.normal)) << zbuffer;
    // And the lens changes the picture: the pinhole is farther from the tracer's image.
    EXPECT_LT(compare_buffers(centre.buffers, traced.buffers).colour.psnr_db, m.colour.psnr_db)
        << zbuffer;
  }
}

// GL's multisampling stays on offer: one pass at the GL's own sample positions, a pinhole,
// which it says.
TEST(AccumulationBuffer, MsaaIsOnePassThroughThePinholeAndSaysSo) {
  const Scene scene = small_builtin_scene("dof");
  const RenderOutput msaa = render("raster", scene, RenderMode::Full, 0, Supersampling::Msaa);
  EXPECT_EQ(msaa.stats.count("zbuffer.accumulation_passes"), 0u);
  bool said = false;
  for (const std::string& w : msaa.warnings)
    said |= w.find("depth of field (aperture_radius > 0) not rendered by --supersampling msaa") !=
            std::string::npos;
  EXPECT_TRUE(said);
}

// The passes of one render share their shadow maps, and only they: a renderer that rendered
// another scene's passes before draws this scene's maps afresh (the same bytes as a new
// renderer's), and sharing changes no byte of the image.
TEST(AccumulationBuffer, PassesShareOnlyTheirOwnRendersShadowMaps) {
  Scene first = small_builtin_scene("dof");
  Scene second = first;
  ASSERT_FALSE(second.lights.empty());
  for (Light& light : second.lights) light.position += glm::vec3(1.5f, 0.5f, 0.0f);
  RenderOptions options;
  options.mode = RenderMode::Full;
  for (const char* zbuffer : {"raster", "softraster"}) {
    auto used = make_renderer(zbuffer, GlBackend::OsMesa);
    auto fresh = make_renderer(zbuffer, GlBackend::OsMesa);
    ASSERT_TRUE(used.ok() && fresh.ok()) << zbuffer;
    ASSERT_TRUE(used.value()->render(first, options).ok()) << zbuffer;
    Expected<RenderOutput> again = used.value()->render(second, options);
    Expected<RenderOutput> anew = fresh.value()->render(second, options);
    ASSERT_TRUE(again.ok() && anew.ok()) << zbuffer;
    EXPECT_TRUE(test::same_bytes(again->buffers.colour, anew->buffers.colour)) << zbuffer;
    // The moved light changes the image: had the first scene's maps been kept, it would show.
    Expected<RenderOutput> before = fresh.value()->render(first, options);
    ASSERT_TRUE(before.ok()) << zbuffer;
    EXPECT_FALSE(test::same_bytes(before->buffers.colour, anew->buffers.colour)) << zbuffer;
  }
}

// The passes are the tracer's samples whatever the thread count: the same bytes.
TEST(AccumulationBuffer, SameBytesWithOneAndTwoThreads) {
  const Scene scene = small_builtin_scene("dof");
  const RenderOutput one = render("softraster", scene, RenderMode::Full, 1);
  const RenderOutput two = render("softraster", scene, RenderMode::Full, 2);
  EXPECT_TRUE(test::same_bytes(one.buffers.colour, two.buffers.colour));
  EXPECT_EQ(one.buffers.object_id, two.buffers.object_id);
}

}  // namespace rvr
