// The tracer's PrimaryHitSource interface on its own, without a z-buffer: a source answering
// every block with the tracer's own closest hits must give render()'s frame byte for byte, and
// its sample hits, added by add_samples pass by pass and divided, render()'s supersampled
// colours (cornell: its area light jitters by each sample's own random stream). A source
// calling every block background gives the background and casts no ray.
#include <gtest/gtest.h>
#include <stddef.h>
#include <stdint.h>

#include <glm/glm.hpp>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/isa.h"
#include "rvr/core/ray.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/raytrace/primary_hit_source.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh_layout.h"
#include "rvr/scene_io/scene_loader.h"
#include "same_bytes.h"

using namespace rvr;

namespace {

// Every hit is the tracer's own: closest_packet for the centre rays, closest for the samples.
class ClosestHits : public PrimaryHitSource {
 public:
  explicit ClosestHits(const TraceGeometry& geometry) : geometry_(geometry) {}
  bool only_background(int, int, int, int) const override { return false; }
  void centre_hits(CentreBlock& block) const override {
    geometry_.closest_packet(block.packet, block.hits, block.work);
    for (int k = 0; k < block.packet.count; ++k) block.given[k] = false;
    block.rays = uint64_t(block.packet.count);
  }
  void sample_hits(SampleBlock& block) const override {
    const int n = (block.x1 - block.x0) * (block.y1 - block.y0);
    for (int j = 0; j < n; ++j) {
      block.hits[j] = HitRecord{};
      if (!geometry_.closest(block.rays[j], block.hits[j], block.work)) block.hits[j] = HitRecord{};
      block.given[j] = false;
    }
  }

 private:
  const TraceGeometry& geometry_;
};

class NothingButBackground : public ClosestHits {
 public:
  using ClosestHits::ClosestHits;
  bool only_background(int, int, int, int) const override { return true; }
};

using rvr::test::same_bytes;

Scene small_scene(const std::string& name, int samples_per_pixel) {
  Scene scene = make_builtin_scene(name).value();
  scene.image.width = 72;
  scene.image.height = 56;
  scene.image.samples_per_pixel = samples_per_pixel;
  return scene;
}

RenderOptions full_mode() {
  RenderOptions options;
  options.mode = RenderMode::Full;
  options.cost_aov = true;
  return options;
}

}  // namespace

TEST(PrimaryHitSource, TheTracersOwnHitsGiveRendersFrame) {
  for (const char* name : {"cornell", "csg", "textured", "glass"}) {
    const Scene scene = small_scene(name, 1);
    const RenderOptions options = full_mode();
    TraceGeometry geometry(scene, options.spheres, options.sphere_segments, options.accel,
                           options.triangle_test, options.isa);
    ASSERT_TRUE(geometry.error().empty()) << geometry.error();
    RayTracer tracer;
    const RenderOutput own = tracer.render(scene, options, geometry).value();
    const RenderOutput given =
        tracer.render(scene, options, geometry, ClosestHits(geometry)).value();
    const FrameBuffers &a = own.buffers, &b = given.buffers;
    EXPECT_TRUE(same_bytes(a.colour, b.colour)) << name;
    EXPECT_TRUE(same_bytes(a.depth, b.depth)) << name;
    EXPECT_TRUE(same_bytes(a.object_id, b.object_id)) << name;
    EXPECT_TRUE(same_bytes(a.primitive_id, b.primitive_id)) << name;
    EXPECT_TRUE(same_bytes(a.normal, b.normal)) << name;
    EXPECT_TRUE(same_bytes(a.cost, b.cost)) << name;
    EXPECT_TRUE(same_bytes(a.lod, b.lod)) << name;
    EXPECT_EQ(own.stats.at("rays.primary"), given.stats.at("rays.primary")) << name;
    EXPECT_EQ(own.stats.at("bvh.nodes_visited"), given.stats.at("bvh.nodes_visited")) << name;
  }
}

TEST(PrimaryHitSource, SamplesAddedPassByPassAreRendersSupersampledColours) {
  for (const char* name : {"cornell", "dof", "textured"}) {
    const Scene scene = small_scene(name, 4);
    const RenderOptions options = full_mode();
    TraceGeometry geometry(scene, options.spheres, options.sphere_segments, options.accel,
                           options.triangle_test, options.isa);
    ASSERT_TRUE(geometry.error().empty()) << geometry.error();
    RayTracer tracer;
    const RenderOutput own = tracer.render(scene, options, geometry).value();
    const ClosestHits source(geometry);
    std::vector<glm::vec3> sum(own.buffers.pixel_count(), glm::vec3(0.0f));
    for (int k = 0; k < scene.image.samples_per_pixel; ++k)
      ASSERT_TRUE(tracer.add_samples(scene, options, geometry, source, k, sum).ok());
    PixelVector<glm::vec3> colour(sum.size());
    for (size_t i = 0; i < sum.size(); ++i)
      colour[i] = sum[i] / float(scene.image.samples_per_pixel);
    EXPECT_TRUE(same_bytes(own.buffers.colour, colour)) << name;
  }
}

TEST(PrimaryHitSource, BackgroundBlocksCastNoRay) {
  const Scene scene = small_scene("cornell", 1);
  const RenderOptions options = full_mode();
  TraceGeometry geometry(scene, options.spheres, options.sphere_segments, options.accel,
                         options.triangle_test, options.isa);
  ASSERT_TRUE(geometry.error().empty()) << geometry.error();
  RayTracer tracer;
  const RenderOutput out =
      tracer.render(scene, options, geometry, NothingButBackground(geometry)).value();
  EXPECT_EQ(out.stats.at("rays.primary"), 0.0);
  EXPECT_EQ(out.stats.at("rays.shadow"), 0.0);
  for (size_t i = 0; i < out.buffers.pixel_count(); ++i) {
    ASSERT_EQ(out.buffers.object_id[i], kNoId) << i;
    ASSERT_EQ(out.buffers.colour[i], scene.image.background) << i;
  }
}

TEST(PrimaryHitSource, AddSamplesRejectsASumOfTheWrongSize) {
  const Scene scene = small_scene("cornell", 2);
  const RenderOptions options = full_mode();
  TraceGeometry geometry(scene, options.spheres, options.sphere_segments, options.accel,
                         options.triangle_test, options.isa);
  RayTracer tracer;
  std::vector<glm::vec3> sum(7);
  EXPECT_FALSE(tracer.add_samples(scene, options, geometry, ClosestHits(geometry), 0, sum).ok());
  std::vector<glm::vec3> whole(size_t(scene.image.width) * size_t(scene.image.height));
  EXPECT_FALSE(tracer.add_samples(scene, options, geometry, ClosestHits(geometry), 2, whole).ok());
}
