// The z-buffers' post-process depth of field (raster/src/depth_of_field_blur.h): its circle of
// confusion against the thin lens's geometry, its blur against the closed form of a disk
// spread over a step, and its error against the tracer between the pinhole's and the
// accumulation buffer's.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "depth_of_field_blur.h"
#include "rvr/compare/compare.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "table_render.h"

namespace rvr {
namespace {

constexpr double kPi = 3.14159265358979323846;

Camera lens_camera() {
  Camera c;
  c.eye = {0.0f, 0.0f, 0.0f};
  c.target = {0.0f, 0.0f, -1.0f};
  c.up = {0.0f, 1.0f, 0.0f};
  c.fov_y_deg = 40.0f;
  c.near = 0.1f;
  c.far = 100.0f;
  c.aperture_radius = 0.1f;
  c.focus_distance = 4.0f;
  return c;
}

// A frame of one depth everywhere: white left of column `edge`, black from it on.
FrameBuffers step_frame(int w, int h, int edge, float depth) {
  FrameBuffers fb;
  fb.reset(w, h, glm::vec3(0.0f));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      fb.colour[fb.index(x, y)] = x < edge ? glm::vec3(1.0f) : glm::vec3(0.0f);
      fb.depth[fb.index(x, y)] = depth;
    }
  return fb;
}

// The share of a disk of radius r, centred s from a straight edge, on the far side of it.
double disk_share_beyond(double s, double r) {
  if (s >= r) return 0.0;
  if (s <= -r) return 1.0;
  return (r * r * std::acos(s / r) - s * std::sqrt(r * r - s * s)) / (kPi * r * r);
}

RenderOutput render_full(const std::string& renderer, const Scene& scene, ZBufferDof dof) {
  RenderOptions options;
  options.mode = RenderMode::Full;
  options.zbuffer_dof = dof;
  return test::table_render(renderer, scene, options);
}

}  // namespace

// The circle of confusion is how far a lens sample's pass (the accumulation buffer's camera)
// moves the image of a point off the pinhole's: for a point on the axis at depth d seen through
// the lens point at the aperture's rim, the two projections differ by exactly the radius.
TEST(DepthOfFieldBlur, CircleOfConfusionIsWhereTheLensRimSeesAPoint) {
  const Camera camera = lens_camera();
  const int w = 200, h = 150;
  ImageSample rim;
  rim.lens_x = camera.aperture_radius;
  for (float d : {1.0f, 2.5f, 4.0f, 7.0f, 30.0f}) {
    const glm::vec4 point(0.0f, 0.0f, -d, 1.0f);
    const glm::vec4 pinhole = sample_projection_matrix(camera, w, h, ImageSample{}) *
                              sample_view_matrix(camera, {}) * point;
    const glm::vec4 lens =
        sample_projection_matrix(camera, w, h, rim) * sample_view_matrix(camera, rim) * point;
    const double shift = 0.5 * double(w) * std::abs(lens.x / lens.w - pinhole.x / pinhole.w);
    EXPECT_NEAR(circle_of_confusion_pixels(camera, h, d), shift, 1e-3 * (1.0 + shift)) << d;
  }
  EXPECT_EQ(circle_of_confusion_pixels(camera, h, camera.focus_distance), 0.0f);
  // The background: the limit of infinite depth.
  EXPECT_NEAR(circle_of_confusion_pixels(camera, h, INFINITY),
              circle_of_confusion_pixels(camera, h, 1e9f), 1e-4);
}

// A step at one depth, spread over disks of one radius: each pixel is the share of its disk
// on the white side (the closed form of a circular segment), to the disk's pixel sampling;
// beyond the radius nothing changes; the focus plane keeps every byte.
TEST(DepthOfFieldBlur, AStepSpreadsAsADiskOverIt) {
  Camera camera = lens_camera();
  const int w = 64, h = 32, edge = 32;
  // The depth whose circle of confusion is 6.3 pixels.
  const double per_tangent = double(h) / (2.0 * std::tan(0.5 * camera.fov_y_deg * kPi / 180.0));
  const double r = 6.3;
  const float depth =
      float(1.0 / (1.0 / camera.focus_distance - r / (per_tangent * camera.aperture_radius)));
  ASSERT_NEAR(circle_of_confusion_pixels(camera, h, depth), r, 1e-3);
  FrameBuffers fb = step_frame(w, h, edge, depth);
  const float widest = blur_depth_of_field(camera, fb, 0);
  EXPECT_NEAR(widest, r, 1e-3);
  const int y = h / 2;
  for (int x = 0; x < w; ++x) {
    const double s = double(x) + 0.5 - double(edge);  // the pixel centre's distance past the edge
    const float got = fb.colour[fb.index(x, y)].r;
    if (std::abs(s) > r + 1.0) {
      EXPECT_EQ(got, s < 0 ? 1.0f : 0.0f) << x;
    } else {
      // A disk of ~125 pixel centres: its share on one side is off the area's by less than
      // the pixels its rim cuts, about 2 pi r of them, half each way: 0.05 at this radius.
      EXPECT_NEAR(got, disk_share_beyond(s, r), 0.05) << x;
    }
    // Symmetric about the edge, as the disk is.
    if (x < edge) {
      EXPECT_NEAR(got + fb.colour[fb.index(w - 1 - x, y)].r, 1.0f, 1e-5f) << x;
    }
  }
  FrameBuffers sharp = step_frame(w, h, edge, camera.focus_distance);
  const FrameBuffers before = sharp;
  EXPECT_EQ(blur_depth_of_field(camera, sharp, 0), 0.0f);
  EXPECT_EQ(sharp.colour, before.colour);
}

// A surface at the focus plane in front of a defocused one stays sharp to the byte: the blurred
// surface behind covers a pixel in front only within the front pixel's own circle (none).
TEST(DepthOfFieldBlur, ABlurredBackgroundDoesNotSpreadOverASharpSurfaceInFront) {
  Camera camera = lens_camera();
  camera.aperture_radius = 0.4f;
  const int w = 48, h = 48;
  FrameBuffers fb;
  fb.reset(w, h, glm::vec3(0.0f));
  const glm::vec3 red(1.0f, 0.0f, 0.0f), blue(0.0f, 0.0f, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool square = x >= 16 && x < 32 && y >= 16 && y < 32;
      fb.colour[fb.index(x, y)] = square ? red : blue;
      fb.depth[fb.index(x, y)] = square ? camera.focus_distance : 40.0f;
    }
  ASSERT_GT(circle_of_confusion_pixels(camera, h, 40.0f), 3.0f);
  blur_depth_of_field(camera, fb, 0);
  for (int y = 16; y < 32; ++y)
    for (int x = 16; x < 32; ++x) EXPECT_EQ(fb.colour[fb.index(x, y)], red) << x << "," << y;
}

// Against the tracer's thin lens, the blur's error lies between that of the one pinhole pass it
// blurs (no depth of field) and the accumulation buffer's (the tracer's own lens samples), and
// the renderer says so.
TEST(DepthOfFieldBlur, ItsErrorLiesBetweenThePinholesAndTheAccumulationBuffers) {
  const Scene scene = test::small_builtin_scene("dof");
  Scene pinhole = scene;
  pinhole.camera.aperture_radius = 0.0f;
  pinhole.image.samples_per_pixel = 1;
  const RenderOutput traced = render_full("raytrace", scene, ZBufferDof::Accumulation);
  for (const char* zbuffer : {"raster", "softraster"}) {
    const RenderOutput blurred = render_full(zbuffer, scene, ZBufferDof::Blur);
    const RenderOutput accumulated = render_full(zbuffer, scene, ZBufferDof::Accumulation);
    const RenderOutput sharp = render_full(zbuffer, pinhole, ZBufferDof::Accumulation);
    const double blur_db = compare_buffers(blurred.buffers, traced.buffers).colour.psnr_db;
    const double lens_db = compare_buffers(accumulated.buffers, traced.buffers).colour.psnr_db;
    const double pinhole_db = compare_buffers(sharp.buffers, traced.buffers).colour.psnr_db;
    EXPECT_GT(blur_db, pinhole_db + 1.0) << zbuffer;
    EXPECT_LT(blur_db, lens_db) << zbuffer;
    RecordProperty(std::string(zbuffer) + "_blur_psnr_db", std::to_string(blur_db));
    EXPECT_GT(blurred.stats.at("dof.blur_radius"), 1.0) << zbuffer;
    EXPECT_EQ(blurred.stats.count("zbuffer.accumulation_passes"), 0u) << zbuffer;
    bool said = false;
    for (const std::string& w : blurred.warnings)
      said |= w.find("depth of field by blur") != std::string::npos;
    EXPECT_TRUE(said) << zbuffer;
  }
}

}  // namespace rvr
