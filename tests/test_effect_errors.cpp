// The colour error where each effect acts (rvr/compare/effect_errors.h), held to hand-made
// frames whose errors are known in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <initializer_list>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/compare/effect_errors.h"
#include "rvr/core/effect_answer.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/image_codec/image_io.h"

namespace rvr {
namespace {

// Objects 0..3: matt, mirror (0.5), glass, a CSG solid; materials 1..3 for the first three.
Scene four_objects() {
  Scene s;
  s.materials.resize(4);
  s.materials[2].mirror = 0.5f;
  s.materials[3].transparency = 0.9f;
  s.objects.resize(4);
  for (uint32_t i = 0; i < 3; ++i) s.objects[i].material = i + 1;
  s.objects[3].type = ObjectType::Csg;
  s.objects[3].material = 1;
  s.image.width = 5;
  s.image.height = 1;
  return s;
}

// A 5x1 frame: pixels 0..3 show objects 0..3, pixel 4 the background.
FrameBuffers frame(const std::vector<glm::vec3>& colours) {
  FrameBuffers fb;
  fb.width = 5;
  fb.height = 1;
  fb.object_id.assign({0, 1, 2, 3, kNoId});
  fb.colour.assign(colours.begin(), colours.end());
  return fb;
}

const EffectError* find(const std::vector<EffectError>& errors, const std::string& name) {
  for (const EffectError& e : errors)
    if (e.effect == name) return &e;
  return nullptr;
}

// a and b differ by 0.3 in one channel on the mirror's pixel, 0.6 in all three on the glass's
// and 0.1 in one on the CSG solid's; the matt object and the background agree.
TEST(EffectErrors, EachMaskHoldsItsEffectsPixelsAndTheirErrorOnly) {
  const Scene scene = four_objects();
  const FrameBuffers a =
      frame({glm::vec3(0.2f), glm::vec3(0.5f), glm::vec3(0.4f), glm::vec3(0.1f), glm::vec3(0.0f)});
  FrameBuffers b = a;
  b.colour[1].y += 0.3f;
  b.colour[2] += glm::vec3(0.6f);
  b.colour[3].z -= 0.1f;
  const std::vector<EffectError> full = effect_errors(scene, RenderMode::Full, a, a, b);
  ASSERT_EQ(full.size(), 3u);  // no lens: the camera is a pinhole
  EXPECT_EQ(full[0].effect, "reflection");
  EXPECT_EQ(full[1].effect, "refraction");
  EXPECT_EQ(full[2].effect, "csg");
  // One pixel each: rmse over its three channels, sqrt(d^2 / 3) for one channel off by d.
  EXPECT_EQ(full[0].pixels, 1u);
  EXPECT_NEAR(full[0].rmse, 0.3 / std::sqrt(3.0), 1e-6);
  EXPECT_NEAR(full[0].max_abs, 0.3, 1e-6);
  EXPECT_NEAR(full[0].psnr_db, 20.0 * std::log10(std::sqrt(3.0) / 0.3), 1e-4);
  EXPECT_NEAR(full[1].rmse, 0.6, 1e-6);
  EXPECT_NEAR(full[2].rmse, 0.1 / std::sqrt(3.0), 1e-6);
  // Local mode shades no mirror or glass: only the CSG solid is an effect there.
  const std::vector<EffectError> local = effect_errors(scene, RenderMode::Local, a, a, b);
  ASSERT_EQ(local.size(), 1u);
  EXPECT_EQ(local[0].effect, "csg");
}

// With a lens (full mode, an aperture, several samples) every pixel depends on it, background
// included; a mask read from a frame that sees other objects follows that frame.
TEST(EffectErrors, TheLensCoversEveryPixelAndMasksFollowTheGivenFrame) {
  Scene scene = four_objects();
  scene.camera.aperture_radius = 0.1f;
  scene.image.samples_per_pixel = 4;
  const FrameBuffers a = frame(std::vector<glm::vec3>(5, glm::vec3(0.5f)));
  FrameBuffers b = a;
  b.colour[4].x = 0.9f;  // the background differs by 0.4 in one channel
  const std::vector<EffectError> errors = effect_errors(scene, RenderMode::Full, a, a, b);
  const EffectError* lens = find(errors, "lens");
  ASSERT_NE(lens, nullptr);
  EXPECT_EQ(lens->pixels, 5u);
  EXPECT_NEAR(lens->rmse, 0.4 / std::sqrt(15.0), 1e-6);
  const EffectError* mirror = find(errors, "reflection");
  ASSERT_NE(mirror, nullptr);
  EXPECT_EQ(mirror->psnr_db, std::numeric_limits<double>::infinity());  // identical there
  // The same colours, the mask from a frame in which pixel 4 shows the mirror too.
  FrameBuffers masks = a;
  masks.object_id[4] = 1;
  const std::vector<EffectError> wider_errors = effect_errors(scene, RenderMode::Full, masks, a, b);
  const EffectError* wider = find(wider_errors, "reflection");
  ASSERT_NE(wider, nullptr);
  EXPECT_EQ(wider->pixels, 2u);
  EXPECT_NEAR(wider->rmse, 0.4 / std::sqrt(6.0), 1e-6);
}

// effects.png: the mirror's pixel in the reflection's key colour, the glass's in the
// refraction's, the CSG solid's in csg's; the matt object's and the background's grey.
TEST(EffectErrors, TheMaskImageColoursEachEffectsPixels) {
  const Scene scene = four_objects();
  const FrameBuffers a = frame(std::vector<glm::vec3>(5, glm::vec3(0.5f)));
  const Image img = effect_mask_image(scene, RenderMode::Full, a);
  ASSERT_EQ(img.pixels.size(), 15u);
  auto pixel = [&](size_t i) {
    return glm::vec3(img.pixels[3 * i], img.pixels[3 * i + 1], img.pixels[3 * i + 2]);
  };
  auto key = [](size_t k) {
    return glm::vec3(kEffectKeys[k].rgb[0], kEffectKeys[k].rgb[1], kEffectKeys[k].rgb[2]);
  };
  EXPECT_EQ(pixel(1), key(0));  // reflection
  EXPECT_EQ(pixel(2), key(1));  // refraction
  EXPECT_EQ(pixel(3), key(3));  // csg
  for (size_t grey : {0u, 4u}) {
    EXPECT_EQ(pixel(grey).x, pixel(grey).y);
    EXPECT_EQ(pixel(grey).y, pixel(grey).z);
    EXPECT_LT(pixel(grey).x, 0.6f);
  }
}

// A z-buffer's answers split each mask: the mirror's pixel and the glass's answered by cube
// maps, a second mirror pixel (the background's, masked by a frame that sees the mirror there)
// by screen-space reflections off screen. Each answer's error is its own pixels' alone; the
// answers are read from the frame that holds them, a's before b's, and absent when neither does.
TEST(EffectErrors, AnswersSplitEachMaskByTechnique) {
  const Scene scene = four_objects();
  const FrameBuffers a =
      frame({glm::vec3(0.2f), glm::vec3(0.5f), glm::vec3(0.4f), glm::vec3(0.1f), glm::vec3(0.0f)});
  FrameBuffers b = a;
  b.colour[1].y += 0.3f;
  b.colour[4].x += 0.6f;
  FrameBuffers masks = a;
  masks.object_id[4] = 1;
  FrameBuffers answered = b;
  answered.answer = {0, uint8_t(EffectAnswer::CubeMapReflection),
                     uint8_t(EffectAnswer::CubeMapRefraction), 0,
                     uint8_t(EffectAnswer::SsrOffScreen)};
  EXPECT_EQ(answering_frame(a, answered), &answered);
  EXPECT_EQ(answering_frame(answered, a), &answered);
  EXPECT_EQ(answering_frame(a, b), nullptr);
  const std::vector<EffectError> errors =
      effect_errors(scene, RenderMode::Full, masks, a, answered);
  const EffectError* reflection = find(errors, "reflection");
  ASSERT_NE(reflection, nullptr);
  EXPECT_EQ(reflection->pixels, 2u);
  ASSERT_EQ(reflection->answers.size(), 2u);
  EXPECT_EQ(reflection->answers[0].answer, "cube_map_reflection");
  EXPECT_EQ(reflection->answers[0].pixels, 1u);
  EXPECT_NEAR(reflection->answers[0].rmse, 0.3 / std::sqrt(3.0), 1e-6);
  EXPECT_EQ(reflection->answers[1].answer, "ssr_off_screen");
  EXPECT_NEAR(reflection->answers[1].rmse, 0.6 / std::sqrt(3.0), 1e-6);
  EXPECT_NEAR(reflection->answers[1].max_abs, 0.6, 1e-6);
  const EffectError* refraction = find(errors, "refraction");
  ASSERT_NE(refraction, nullptr);
  ASSERT_EQ(refraction->answers.size(), 1u);
  EXPECT_EQ(refraction->answers[0].answer, "cube_map_refraction");
  EXPECT_EQ(refraction->answers[0].psnr_db, std::numeric_limits<double>::infinity());
  // The CSG solid's pixel: answered by nothing the z-buffer records.
  const EffectError* csg = find(errors, "csg");
  ASSERT_NE(csg, nullptr);
  ASSERT_EQ(csg->answers.size(), 1u);
  EXPECT_EQ(csg->answers[0].answer, "none");
  // Without answers in either frame, no split.
  for (const EffectError& e : effect_errors(scene, RenderMode::Full, masks, a, b))
    EXPECT_TRUE(e.answers.empty()) << e.effect;
  // answers.png: the answered pixels in their answer's colour, the others grey.
  const Image img = answer_image(answered);
  ASSERT_EQ(img.pixels.size(), 15u);
  const auto pixel = [&](size_t i) {
    return glm::vec3(img.pixels[3 * i], img.pixels[3 * i + 1], img.pixels[3 * i + 2]);
  };
  const auto colour = [](EffectAnswer k) {
    const float* c = kAnswerColours[size_t(k)];
    return glm::vec3(c[0], c[1], c[2]);
  };
  EXPECT_EQ(pixel(1), colour(EffectAnswer::CubeMapReflection));
  EXPECT_EQ(pixel(4), colour(EffectAnswer::SsrOffScreen));
  EXPECT_EQ(pixel(0).x, pixel(0).y);
  EXPECT_EQ(pixel(3).y, pixel(3).z);
}

// The mask's SSIM is the mean of the whole image's SSIM map over the mask: a 40x10 frame whose
// right half is the mirror, b changed only in its last ten columns, so the matt left half (its
// window reaches 5 columns) keeps SSIM 1 exactly and the whole image's mean (compare_buffers)
// is (20·10·1 + 200·mask SSIM) / 400. Identical frames give 1.
TEST(EffectErrors, TheMaskSsimIsTheImagesSsimMapAveragedOverTheMask) {
  Scene scene = four_objects();
  scene.image.width = 40;
  scene.image.height = 10;
  FrameBuffers a;
  a.reset(40, 10, glm::vec3(0.0f));
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 40; ++x) {
      const size_t i = a.index(x, y);
      a.object_id[i] = x < 20 ? 0u : 1u;
      a.primitive_id[i] = 0u;
      a.depth[i] = 1.0f;
      a.colour[i] = glm::vec3(0.2f + 0.015f * float(x), 0.4f, 0.3f + 0.02f * float(y));
    }
  FrameBuffers b = a;
  for (int y = 0; y < 10; ++y)
    for (int x = 30; x < 40; ++x)
      b.colour[size_t(y) * 40 + size_t(x)] = glm::vec3((x + y) % 2 == 0 ? 0.9f : 0.1f);
  const std::vector<EffectError> errors = effect_errors(scene, RenderMode::Full, a, a, b);
  const EffectError* reflection = find(errors, "reflection");
  ASSERT_NE(reflection, nullptr);
  EXPECT_EQ(reflection->pixels, 200u);
  EXPECT_LT(reflection->ssim, 0.9);
  const double whole = compare_buffers(a, b).colour.ssim;
  EXPECT_NEAR(reflection->ssim, (400.0 * whole - 200.0) / 200.0, 1e-9);
  // Split by answers (the mirror's columns 20-29 one, 30-39 another): each part's mean, and
  // together the mask's.
  FrameBuffers answered = b;
  answered.answer.assign(answered.pixel_count(), 0);
  for (int y = 0; y < 10; ++y)
    for (int x = 20; x < 40; ++x)
      answered.answer[answered.index(x, y)] =
          uint8_t(x < 30 ? EffectAnswer::ReflectedView : EffectAnswer::CubeMapReflection);
  const std::vector<EffectError> split_errors =
      effect_errors(scene, RenderMode::Full, a, a, answered);
  const EffectError* split = find(split_errors, "reflection");
  ASSERT_NE(split, nullptr);
  ASSERT_EQ(split->answers.size(), 2u);
  EXPECT_NEAR(split->answers[0].ssim + split->answers[1].ssim, 2.0 * reflection->ssim, 1e-9);
  EXPECT_LT(split->answers[1].ssim, split->answers[0].ssim);
  EXPECT_LT(split->answers[0].ssim, 1.0);
  const std::vector<EffectError> same_errors = effect_errors(scene, RenderMode::Full, a, a, a);
  const EffectError* same = find(same_errors, "reflection");
  ASSERT_NE(same, nullptr);
  EXPECT_EQ(same->ssim, 1.0);
}

// Frames of another size than the mask's: nothing is measured rather than read out of range.
TEST(EffectErrors, MismatchedFramesGiveNoFigures) {
  const Scene scene = four_objects();
  const FrameBuffers a = frame(std::vector<glm::vec3>(5, glm::vec3(0.5f)));
  FrameBuffers small = a;
  small.colour.resize(3);
  EXPECT_TRUE(effect_errors(scene, RenderMode::Full, a, a, small).empty());
}

}  // namespace
}  // namespace rvr
