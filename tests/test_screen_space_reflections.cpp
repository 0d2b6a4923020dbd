// Screen-space reflections (raster/src/screen_space_reflections.h) over a frame softraster drew:
// rays whose fate is known in closed form (the wall they meet, where it lands on screen; the
// occluder in front of it; the view's edge; the sky) must come back as that outcome, a hit with
// the colour of the wall where the ray meets it.
#include <gtest/gtest.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <utility>

#include "pass_camera.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/raster/soft_rasterizer.h"
#include "scene_builders.h"
#include "screen_space_reflections.h"

namespace rvr {
namespace {

// A glowing floor (y = 0) and back wall (z = -5, up to y = 3), an occluding square in front of
// the wall's left part, the sky (background) above the wall; the camera looks at the wall.
struct Frame {
  Scene scene;
  FrameBuffers fb;
  PassCamera camera;
};

constexpr glm::vec3 kFloor{0.2f, 0.6f, 0.3f}, kWall{0.8f, 0.3f, 0.1f}, kOccluder{0.1f, 0.2f, 0.9f};
constexpr glm::vec3 kSky{0.0f, 0.0f, 0.05f};

Frame draw() {
  Frame f;
  Scene& s = f.scene;
  s = test::empty_scene(200, 150, {0.0f, 1.5f, 4.0f}, {0.0f, 1.2f, -5.0f}, 50.0f);
  s.image.background = kSky;
  test::add_plane(s, {0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 20.0f, test::emissive(s, kFloor));
  test::add_plane(s, {0.0f, 1.5f, -5.0f}, {0.0f, 0.0f, 1.0f}, 2.0f, test::emissive(s, kWall));
  test::add_plane(s, {-1.5f, 1.5f, -2.0f}, {0.0f, 0.0f, 1.0f}, 0.5f, test::emissive(s, kOccluder));
  RenderOptions options;
  options.mode = RenderMode::Local;
  SoftRasterizer r;
  Expected<RenderOutput> out = r.render(s, options);
  EXPECT_TRUE(out.ok());
  if (out.ok()) f.fb = std::move(out->buffers);
  f.camera = pass_camera(s, options);
  return f;
}

constexpr uint32_t kNothing = 1000;  // no such object: the ray leaves nothing behind

SsrOutcome trace(const Frame& f, glm::dvec3 p, glm::dvec3 r, glm::vec3& colour) {
  const ScreenSpaceReflections ssr(f.fb, f.camera, double(f.scene.camera.near), 100.0);
  return ssr.trace(p, glm::normalize(r), kNothing, colour);
}

bool same(const glm::vec3& a, const glm::vec3& b) {
  return glm::all(glm::lessThan(glm::abs(a - b), glm::vec3(1e-6f)));
}

TEST(ScreenSpaceReflections, MeetsTheWallItsRayMeets) {
  const Frame f = draw();
  // From the air in front of the camera, along the view towards the wall's right half.
  glm::vec3 c(-1.0f);
  EXPECT_EQ(trace(f, {1.0, 1.6, 0.0}, {0.1, 0.0, -1.0}, c), SsrOutcome::Hit);
  EXPECT_TRUE(same(c, kWall)) << c.x << " " << c.y << " " << c.z;
  // Down to the floor, on screen in front of the wall.
  EXPECT_EQ(trace(f, {0.5, 1.0, -1.0}, {0.0, -1.0, -0.3}, c), SsrOutcome::Hit);
  EXPECT_TRUE(same(c, kFloor));
}

TEST(ScreenSpaceReflections, PassingBehindTheOccluderIsHidden) {
  const Frame f = draw();
  glm::vec3 c(-1.0f);
  // From just behind the occluder (z = -2, x in [-2, -1]) to the wall behind it: the ray's
  // pixels are the occluder's, which lies in front of it all the way.
  EXPECT_EQ(trace(f, {-1.5, 1.5, -2.3}, {0.0, 0.0, -1.0}, c), SsrOutcome::Hidden);
}

TEST(ScreenSpaceReflections, TowardsTheCameraOrOutOfTheViewIsOffScreen) {
  const Frame f = draw();
  glm::vec3 c(-1.0f);
  EXPECT_EQ(trace(f, {0.0, 1.5, 0.0}, {0.0, 0.0, 1.0}, c),
            SsrOutcome::OffScreen);  // behind the eye
  EXPECT_EQ(trace(f, {0.0, 1.5, 0.0}, {1.0, 0.0, 0.05}, c), SsrOutcome::OffScreen);  // sideways
}

TEST(ScreenSpaceReflections, OverTheWallIntoTheSkyMeetsNothing) {
  const Frame f = draw();
  glm::vec3 c(-1.0f);
  // Over the wall's top edge (y = 3.5 at z = -5) and on, rising into the sky, on screen to the
  // end of the scene.
  EXPECT_EQ(trace(f, {0.0, 3.0, -3.0}, {0.0, 0.3, -1.0}, c), SsrOutcome::Background);
  // Level, just over the wall's top edge: beyond the wall it sinks on screen towards the horizon,
  // behind the wall: what it meets is hidden.
  EXPECT_EQ(trace(f, {0.0, 3.7, -4.5}, {0.0, 0.0, -1.0}, c), SsrOutcome::Hidden);
}

}  // namespace
}  // namespace rvr
