// The ray tracer's frame loop: for each pixel (tiles in parallel), for each object (through
// the BVH or the plain loop), shade the nearest hit with the shared shading function.
#include "rvr/raytrace/ray_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>
#include <tbb/version.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <variant>
#include <vector>

#include "ray_counters.h"
#include "ray_footprint.h"
#include "rvr/core/camera.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/progress.h"
#include "rvr/core/ray.h"
#include "rvr/core/shade_batch.h"
#include "rvr/core/shade_kernel.h"
#include "rvr/core/shading.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/surface_colour.h"
#include "rvr/core/texture.h"
#include "rvr/core/timer.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/intersect.h"
#include "rvr/raytrace/packet_slots.h"
#include "rvr/raytrace/primary_hit_source.h"
#include "rvr/raytrace/primary_rays.h"
#include "rvr/raytrace/screen_bounds.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh.h"
#include "rvr/raytrace/wide_bvh_layout.h"
#include "tile_output.h"

namespace rvr {
namespace {

// Tiles run in parallel, each staged in a TileOutput: wide and short, so that each writes long
// runs of every buffer's rows.
constexpr int kTileWidth = TileOutput::kMaxWidth, kTileHeight = TileOutput::kMaxHeight;

using Clock = std::chrono::steady_clock;

// One random stream per pixel, seeded from (seed, x, y): the image does not depend on which
// thread renders which tile.
class PixelRng {
 public:
  PixelRng(uint64_t seed, int x, int y)
      : state_(seed * 0x9E3779B97F4A7C15ull ^ (uint64_t(uint32_t(x)) << 32 | uint32_t(y))) {
    next();
  }
  // Sample k's own stream: a sample's random numbers do not depend on the samples before it,
  // so a caller can have sample k of every pixel traced in its own pass (add_samples) and draw
  // the same numbers.
  PixelRng(uint64_t seed, int x, int y, int k) : PixelRng(seed, x, y) {
    state_ ^= (uint64_t(uint32_t(k)) + 1) * 0xD1B54A32D192ED03ull;
    next();
  }
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  float uniform() { return float(next() >> 40) * (1.0f / 16777216.0f); }

 private:
  uint64_t state_;
};

// The lod AOV where the surface hit is not textured.
constexpr float kNoLod = std::numeric_limits<float>::quiet_NaN();

// Offset for secondary ray origins: large enough to leave the surface at this position's
// float precision, small enough not to skip thin geometry.
float ray_epsilon(const glm::vec3& p) {
  float m = std::max(std::max(std::abs(p.x), std::abs(p.y)), std::max(std::abs(p.z), 1.0f));
  return 1e-4f * m;
}

class FrameTracer {
 public:
  FrameTracer(const Scene& scene, const RenderOptions& options, const TraceGeometry& geometry,
              const ShadeKernels& kernels)
      : scene_(scene),
        options_(options),
        geometry_(geometry),
        lights_(light_samples(scene.lights)),
        frame_(make_camera_frame(scene.camera, scene.image.width, scene.image.height)),
        rays_(frame_, scene.camera.near, scene.camera.far),
        thin_lens_(options.mode == RenderMode::Full && scene.camera.aperture_radius > 0.0f),
        kernels_(kernels),
        light_arrays_(lights_),
        primary_footprint_(rvr::primary_footprint(frame_)),
        scene_rect_(screen_bounds(frame_, scene.camera.near, geometry.bounds())) {
    materials_.reserve(scene.materials.size());
    for (const Material& m : scene.materials)
      materials_.push_back(shade_material(m, scene.ambient));
    object_varies_.reserve(scene.objects.size());
    object_textured_.reserve(scene.objects.size());
    for (const Object& o : scene.objects) {
      object_varies_.push_back(varies_in_colour(scene, o) ? 1 : 0);
      object_textured_.push_back(textured(scene, o) ? 1 : 0);
      varies_ = varies_ || object_varies_.back();
      textured_ = textured_ || object_textured_.back();
    }
  }

  // A frame whose primary hits come from a PrimaryHitSource: the colour is the centre hit's,
  // the caller adds the samples (add_sample_block).
  void keep_centre_colour() { centre_only_ = true; }

  // Sample k (image_sample `sample`) of each pixel of [x0, x1) x [y0, y1) (at most kPacketRays):
  // its hit from `source`, shaded with the pixel's stream k, its colour added to sum
  // (row-major, the image's width).
  void add_sample_block(int x0, int y0, int x1, int y1, const PrimaryHitSource& source, int k,
                        const ImageSample& sample, glm::vec3* sum, RayCounters& counters) const {
    Ray rays[kPacketRays];
    HitRecord hits[kPacketRays];
    float given_lod[kPacketRays];
    bool given[kPacketRays];
    for (int y = y0, j = 0; y < y1; ++y)
      for (int x = x0; x < x1; ++x, ++j) rays[j] = sample_ray(x, y, sample);
    SampleBlock block{x0, y0, x1, y1, rays, hits, given_lod, given, {}};
    source.sample_hits(block);
    add_traversal(counters, block.work);
    const size_t width = size_t(scene_.image.width);
    for (int y = y0, j = 0; y < y1; ++y)
      for (int x = x0; x < x1; ++x, ++j) {
        PixelRng rng(options_.seed, x, y, k);
        counters.primary++;
        sum[size_t(y) * width + size_t(x)] +=
            shade_hit(rays[j], hits[j], 0, counters, &rng, textured_footprint(),
                      given[j] ? &given_lod[j] : nullptr);
      }
  }

  // The pixels [x0, x1) x [y0, y1) of one tile (at most kPacketSide on a side): their centre
  // rays traced together as one packet, then finished (finish_block).
  // A block outside the scene's screen bounds gets no rays: every pixel is background.
  void render_block(int x0, int y0, int x1, int y1, TileOutput& out, RayCounters& counters) const {
    if (culled(x0, y0, x1, y1, out, counters)) return;
    const RayPacket packet = rays_.packet(x0, y0, x1 - x0, y1 - y0);
    PacketSlots<HitRecord> hits;
    PacketSlots<TraversalCounters> work;
    geometry_.closest_packet(packet, hits.data(), work.data());
    counters.primary += uint64_t(packet.count);
    finish_block(x0, y0, x1 - x0, packet, hits.data(), work.data(), out, counters);
  }

  // The same pixels with their primary hits from `source`.
  void render_block_from(int x0, int y0, int x1, int y1, const PrimaryHitSource& source,
                         TileOutput& out, RayCounters& counters) const {
    if (culled(x0, y0, x1, y1, out, counters)) return;
    if (source.only_background(x0, y0, x1, y1)) {
      write_background(x0, y0, x1, y1, out);
      return;
    }
    const RayPacket packet = rays_.packet(x0, y0, x1 - x0, y1 - y0);
    PacketSlots<HitRecord> hits;
    PacketSlots<TraversalCounters> work;
    float given_lod[kPacketRays];
    bool given[kPacketRays];
    CentreBlock block{x0, y0, x1, y1, packet, hits.data(), work.data(), given_lod, given, 0, {}};
    source.centre_hits(block);
    counters.primary += block.rays;
    add_traversal(counters, block.unattributed);
    finish_block(x0, y0, x1 - x0, packet, hits.data(), work.data(), out, counters, given_lod,
                 given);
  }

 private:
  // Whether the block lies outside the scene's screen bounds: if so its pixels are written as
  // background and counted as culled. A frame whose samples leave from lens points is never culled:
  // those rays may meet what no centre ray can (the blur around a defocused object). Samples
  // jittered in their pixels stay within the bounds' margin. A hybrid's frame takes its samples
  // from its own passes.
  bool culled(int x0, int y0, int x1, int y1, TileOutput& out, RayCounters& counters) const {
    if (thin_lens_ && scene_.image.samples_per_pixel > 1 && !centre_only_) return false;
    if (x1 > scene_rect_.x0 && x0 < scene_rect_.x1 && y1 > scene_rect_.y0 && y0 < scene_rect_.y1)
      return false;
    write_background(x0, y0, x1, y1, out);
    counters.primary_culled += uint64_t(x1 - x0) * uint64_t(y1 - y0);
    return true;
  }

  void write_background(int x0, int y0, int x1, int y1, TileOutput& out) const {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        out.set_background(out.index(x, y), scene_.image.background);
        if (textured_) out.lod[out.index(x, y)] = kNoLod;
      }
  }

  static void add_traversal(RayCounters& counters, const TraversalCounters& work) {
    counters.traversal.nodes_visited += work.nodes_visited;
    counters.traversal.primitive_tests += work.primitive_tests;
  }

  // The traversal work counted so far: nodes visited and primitives tested.
  static uint64_t traced_work(const RayCounters& counters) {
    return counters.traversal.nodes_visited + counters.traversal.primitive_tests;
  }

  // A block's centre hits as finish_block receives them: hits[k] for ray k of `packet` (row by
  // row, w wide, from pixel (x0, y0); primitive kNoPrimitive where it missed), found with
  // work[k]; given_lod[k], where given[k] (both may be null: none), is the texture level of
  // detail ray k's hit samples at instead of its own footprint's (a PrimaryHitSource's).
  struct BlockHits {
    int x0, y0, w;
    const RayPacket& packet;
    const HitRecord* hits;
    const TraversalCounters* work;
    const float* given_lod;
    const bool* given;

    const float* lod_given(int k) const { return given && given[k] ? &given_lod[k] : nullptr; }
    glm::vec3 direction(int k) const {
      return {packet.dir[0][k], packet.dir[1][k], packet.dir[2][k]};
    }
    uint64_t centre_work(int k) const { return work[k].nodes_visited + work[k].primitive_tests; }
    // f(k, x, y, i) for ray k, its pixel (x, y) and the pixel's index i in `out`.
    template <class F>
    void for_each_pixel(const TileOutput& out, F&& f) const {
      const int y1 = y0 + packet.count / w;
      for (int y = y0, k = 0; y < y1; ++y)
        for (int x = x0; x < x0 + w; ++x, ++k) f(k, x, y, out.index(x, y));
    }
  };

  // The pixels of one block once the closest hits of their centre rays are known. Every buffer
  // of every pixel is written into `out`: the AOVs from the centre hit and, by mode, no colour
  // (visibility), the surface and colour computed by the shading kernels for the block's hits as
  // one batch (local), or each pixel's shadow, reflection and refraction rays traced (full).
  void finish_block(int x0, int y0, int w, const RayPacket& packet, const HitRecord* hits,
                    const TraversalCounters* work, TileOutput& out, RayCounters& counters,
                    const float* given_lod = nullptr, const bool* given = nullptr) const {
    const uint64_t start = cycle_ticks();
    const BlockHits block{x0, y0, w, packet, hits, work, given_lod, given};
    geometry_.fetch_surface_data(hits, packet.count, options_.mode == RenderMode::Visibility);
    switch (options_.mode) {
      case RenderMode::Visibility:
        finish_visibility(block, out);
        break;
      case RenderMode::Local:
        finish_local(block, out, counters);
        break;
      case RenderMode::Full:
        finish_full(block, out, counters);
        break;
    }
    TraversalCounters centre;
    for (int k = 0; k < packet.count; ++k) {
      centre.nodes_visited += work[k].nodes_visited;
      centre.primitive_tests += work[k].primitive_tests;
    }
    add_traversal(counters, centre);
    counters.shade_ticks += cycle_ticks() - start;
  }

  // Whether a pixel's colour is the mean of its samples, traced one by one, rather than its
  // centre ray's (shading modes only).
  bool supersampled() const { return scene_.image.samples_per_pixel > 1 && !centre_only_; }

  // A pixel's cost AOV: the traversal work of every ray traced for it.
  float pixel_cost(uint64_t work) const { return options_.cost_aov ? float(work) : 0.0f; }

  // Visibility is the hit's distance and ids: no surface, no shading.
  void finish_visibility(const BlockHits& b, TileOutput& out) const {
    b.for_each_pixel(out, [&](int k, int, int, size_t i) {
      const HitRecord& hit = b.hits[k];
      if (textured_) out.lod[i] = kNoLod;
      if (hit.primitive == kNoPrimitive) {
        out.set_background(i, scene_.image.background);
      } else {
        const auto [object, primitive] = geometry_.hit_ids(hit);
        out.colour[i] = scene_.image.background;
        out.depth[i] = hit.t;  // the direction's forward component is 1: t is view depth
        out.object_id[i] = object;
        out.primitive_id[i] = primitive;
        out.normal[i] = glm::vec3(0.0f);
        if (textured_ && object_textured_[object])
          out.lod[i] = b.given && b.given[k]
                           ? b.given_lod[k]
                           : textured_hit_lod(scene_.objects[object], primitive, b.direction(k),
                                              hit.t, primary_footprint_);
      }
      out.cost[i] = pixel_cost(b.centre_work(k));
    });
  }

  // A block's hits gathered into one SurfaceBatch for the shading kernels: slot j holds the hit
  // of the pixel pixel[j] of `out`. A batch of one material shades with it; a mixed one carries
  // each slot's.
  struct GatheredHits {
    SurfaceBatch batch;
    size_t pixel[kPacketRays];
    int ray[kPacketRays];  // the slot's ray in the block
  };

  // Writes each pixel's level of detail, cost and, where its ray missed, background, and puts the
  // hits whose material `batched(material)` accepts into g.batch, in ray order (their depth and
  // ids into `out`), ready for the kernels. Returns the rays that hit but were not batched.
  template <class Batched>
  uint64_t gather_hits(const BlockHits& b, TileOutput& out, GatheredHits& g,
                       Batched&& batched) const {
    static_assert(kPacketRays <= kShadeBatch, "a block's hits fit one batch");
    SurfaceBatch& batch = g.batch;
    for (int a = 0; a < 3; ++a) batch.origin[a] = b.packet.origin[a];
    LastTriangle last;
    int batch_count = 0;  // kept out of `batch` so that it stays in a register
    bool mixed = false;   // the batch's pixels have more than one material
    uint32_t batch_material = 0;
    size_t pixel[kPacketRays];
    uint64_t hit_rays = 0, unbatched = 0;
    b.for_each_pixel(out, [&](int k, int, int, size_t i) {
      pixel[k] = i;
      if (textured_) out.lod[i] = kNoLod;
      if (b.hits[k].primitive == kNoPrimitive)
        out.set_background(i, scene_.image.background);
      else
        hit_rays |= uint64_t(1) << k;
      out.cost[i] = pixel_cost(b.centre_work(k));  // after set_background's zero
    });
    for (uint64_t m = hit_rays; m != 0; m &= m - 1) {
      const int k = __builtin_ctzll(m);
      const size_t i = pixel[k];
      const HitRecord& hit = b.hits[k];
      const int slot = batch_count;
      const uint32_t material = add_to_batch(batch, slot, b.packet, k, hit, out, i, last);
      if (!batched(material)) {
        unbatched |= uint64_t(1) << k;
        continue;  // the slot is taken by the next hit
      }
      ++batch_count;
      g.pixel[slot] = i;
      g.ray[slot] = k;
      const uint32_t object = out.object_id[i];
      if (varies_ && object_varies_[object]) {
        // Its own material: the diffuse replaced by the base colour at the hit.
        const Material& mat = scene_.materials[material];
        const glm::vec3 base = varying_base_colour(scene_.objects[object], out.primitive_id[i],
                                                   hit.u, hit.v, b.direction(k), hit.t,
                                                   &primary_footprint_, out.lod[i], b.lod_given(k));
        if (!mixed) {
          mixed = true;
          for (int j = 0; j < slot; ++j) put_material(batch, j, materials_[batch_material]);
        }
        put_material(batch, slot, shade_material(with_diffuse(mat, base), scene_.ambient));
      } else {
        if (slot == 0) {
          batch_material = material;
        } else if (!mixed && material != batch_material) {
          mixed = true;  // from now on each slot carries its material
          for (int j = 0; j < slot; ++j) put_material(batch, j, materials_[batch_material]);
        }
        if (mixed) put_material(batch, slot, materials_[material]);
      }
    }
    batch.count = batch_count;
    if (batch_count > 0) {
      pad_batch(batch, mixed);
      batch.material = mixed ? nullptr : &materials_[batch_material];
    }
    return unbatched;
  }

  // Local shading: the block's hits put into one batch, whose surfaces and colours the shading
  // kernels compute together.
  void finish_local(const BlockHits& b, TileOutput& out, RayCounters& counters) const {
    GatheredHits g;
    gather_hits(b, out, g, [](uint32_t) { return true; });
    // A supersampled pixel's colour is its samples' mean, its cost theirs too.
    const bool supersampled = this->supersampled();
    if (supersampled)
      b.for_each_pixel(out, [&](int k, int x, int y, size_t i) {
        const uint64_t before = traced_work(counters);
        out.colour[i] = supersample(x, y, counters);
        out.cost[i] = pixel_cost(b.centre_work(k) + traced_work(counters) - before);
      });
    const SurfaceBatch& batch = g.batch;
    if (batch.count == 0) return;
    kernels_.shade_surfaces(g.batch, light_arrays_.lights(), nullptr);
    for (int slot = 0; slot < batch.count; ++slot) {
      const size_t i = g.pixel[slot];
      out.normal[i] = {batch.shading_normal[0][slot], batch.shading_normal[1][slot],
                       batch.shading_normal[2][slot]};
      if (!supersampled)
        out.colour[i] = {batch.colour[0][slot], batch.colour[1][slot], batch.colour[2][slot]};
    }
  }

  // Whether full shading can take the block's hits as one batch: one sample per pixel (the
  // light samples then fixed, without a pixel's random stream) and few enough light samples for
  // the kernels' visibility arrays. Only a hit on a material that neither reflects nor
  // transmits joins the batch (its colour is its local term: 1 - 0 - 0 is 1).
  bool full_batches() const {
    return !supersampled() && lights_.size() <= size_t(kShadeVisibleLights);
  }
  bool local_only(uint32_t material) const {
    const Material& m = scene_.materials[material];
    return m.mirror == 0.0f && m.transparency == 0.0f;
  }

  // Full shading with the hits on local-only materials as one batch: the kernels give each
  // pixel's point and normal and which light samples need a shadow ray, the rays are traced
  // pixel by pixel, and the kernels shade with their answers: every operation of shade() for
  // such a hit, in its order. The other hits are shaded one at a time (shade_full_pixel).
  void finish_full(const BlockHits& b, TileOutput& out, RayCounters& counters) const {
    if (!full_batches()) {
      b.for_each_pixel(out, [&](int k, int x, int y, size_t i) {
        shade_full_pixel(b, k, x, y, i, out, counters);
      });
      return;
    }
    GatheredHits g;
    const uint64_t unbatched =
        gather_hits(b, out, g, [&](uint32_t material) { return local_only(material); });
    if (unbatched != 0)
      b.for_each_pixel(out, [&](int k, int x, int y, size_t i) {
        if (unbatched >> k & 1) shade_full_pixel(b, k, x, y, i, out, counters);
      });
    SurfaceBatch& batch = g.batch;
    if (batch.count == 0) return;
    const ShadeLights lights = light_arrays_.lights();
    LightNeeds needs;
    kernels_.light_needs(batch, lights, needs);
    // Every lane the kernel reads is set: 1 where no ray is traced (the kernel adds no term
    // there), the padding lanes included.
    LightVisibility visibility;
    const int lanes = (batch.count + kShadeMaxLanes - 1) / kShadeMaxLanes * kShadeMaxLanes;
    for (int l = 0; l < lights.count; ++l) std::fill_n(visibility.vis[l], lanes, 1.0f);
    for (int slot = 0; slot < batch.count; ++slot) {
      const uint64_t before = traced_work(counters);
      const glm::vec3 P(batch.position[0][slot], batch.position[1][slot], batch.position[2][slot]);
      const glm::vec3 N(batch.shading_normal[0][slot], batch.shading_normal[1][slot],
                        batch.shading_normal[2][slot]);
      const glm::vec3 above = P + ray_epsilon(P) * N;  // as shade() leaves the surface
      for (int l = 0; l < lights.count; ++l)
        if (needs.at(l, slot))
          visibility.vis[l][slot] = shadow_visibility(above, lights_[size_t(l)].position, counters);
      const size_t i = g.pixel[slot];
      out.normal[i] = N;
      out.cost[i] = pixel_cost(b.centre_work(g.ray[slot]) + traced_work(counters) - before);
    }
    kernels_.shade_surfaces(batch, lights, &visibility);
    for (int slot = 0; slot < batch.count; ++slot)
      out.colour[g.pixel[slot]] = {batch.colour[0][slot], batch.colour[1][slot],
                                   batch.colour[2][slot]};
  }

  // Full shading of one pixel (ray k of the block, pixel (x, y), index i): its centre hit's
  // shadow, reflection and refraction rays traced; with several samples, the samples' mean.
  void shade_full_pixel(const BlockHits& b, int k, int x, int y, size_t i, TileOutput& out,
                        RayCounters& counters) const {
    const HitRecord& hit = b.hits[k];
    const uint64_t before = traced_work(counters);
    if (textured_) out.lod[i] = kNoLod;
    if (hit.primitive == kNoPrimitive) {
      out.set_background(i, scene_.image.background);
    } else {
      const Ray ray = PrimaryRays::ray_of(b.packet, k);
      const SurfaceHit s = geometry_.surface(ray, hit);
      const glm::vec3 V = -glm::normalize(ray.dir);
      const glm::vec3 N = face_viewer(s.shading_normal, s.geometric_normal, V);
      out.depth[i] = s.t;
      out.object_id[i] = s.object;
      out.primitive_id[i] = s.primitive;
      out.normal[i] = N;
      out.colour[i] = shade(ray, s, N, V, 0, counters, nullptr, textured_footprint(),
                            textured_ ? &out.lod[i] : nullptr, b.lod_given(k));
    }
    if (supersampled()) out.colour[i] = supersample(x, y, counters);
    out.cost[i] = pixel_cost(b.centre_work(k) + traced_work(counters) - before);
  }

  // vis of a light sample at `light` seen from `above` (a point just off the surface): 0 where
  // the shadow ray meets anything before it, else 1.
  float shadow_visibility(const glm::vec3& above, const glm::vec3& light,
                          RayCounters& counters) const {
    Ray shadow{above, light - above, 0.0f, 1.0f - 1e-4f};
    counters.shadow++;
    return geometry_.occluded(shadow, counters.traversal) ? 0.0f : 1.0f;
  }

  // The surface data of the triangle the last hit put into a batch was on: neighbouring pixels
  // mostly show one triangle, whose data is then read once (as softraster's shading keeps the
  // last triangle it gathered).
  struct LastTriangle {
    uint32_t primitive = kNoPrimitive;
    TriangleSurfaceData data;
  };

  // Puts ray k's hit into slot `slot` of the batch, for the kernel to compute its surface, and
  // its depth and ids into pixel i of `out`; returns its material. Every input of the slot is
  // written (zeros where the kernel selects it away), so no lane reads undefined memory.
  uint32_t add_to_batch(SurfaceBatch& batch, int slot, const RayPacket& packet, int k,
                        const HitRecord& hit, TileOutput& out, size_t i, LastTriangle& last) const {
    const glm::vec3 zero(0.0f);
    batch.t[slot] = hit.t;
    for (int a = 0; a < 3; ++a) batch.direction[a][slot] = packet.dir[a][k];
    out.depth[i] = hit.t;  // the direction's forward component is 1: t is view depth
    if (hit.primitive < geometry_.triangle_count()) {
      if (hit.primitive != last.primitive) {
        last.primitive = hit.primitive;
        last.data = geometry_.triangle_surface_data(hit.primitive);
      }
      const TriangleSurfaceData& d = last.data;
      batch.u[slot] = hit.u;
      batch.v[slot] = hit.v;
      put_vec3(batch.edge1, slot, d.triangle->e1);
      put_vec3(batch.edge2, slot, d.triangle->e2);
      const bool smooth = d.normal[0] != nullptr;
      for (int c = 0; c < 3; ++c)
        put_vec3(batch.vertex_normal[c], slot, smooth ? *d.normal[c] : zero);
      batch.smooth[slot] = smooth ? ~0u : 0u;
      batch.given[slot] = 0u;
      put_vec3(batch.geometric, slot, zero);
      put_vec3(batch.shading, slot, zero);
      out.object_id[i] = d.object;
      out.primitive_id[i] = d.primitive;
      return d.material;
    }
    // Spheres, squares and CSG solids: their surface as surface() gives it.
    const SurfaceHit s = geometry_.surface(PrimaryRays::ray_of(packet, k), hit);
    batch.u[slot] = 0.0f;
    batch.v[slot] = 0.0f;
    put_vec3(batch.edge1, slot, zero);
    put_vec3(batch.edge2, slot, zero);
    for (int c = 0; c < 3; ++c) put_vec3(batch.vertex_normal[c], slot, zero);
    batch.smooth[slot] = 0u;
    batch.given[slot] = ~0u;
    put_vec3(batch.geometric, slot, s.geometric_normal);
    put_vec3(batch.shading, slot, s.shading_normal);
    out.object_id[i] = s.object;
    out.primitive_id[i] = s.primitive;
    return s.material;
  }

  // The samples of image_sample (the same place in every pixel, and with an aperture the same
  // lens point: the accumulation buffer's passes), each with its own random stream.
  glm::vec3 supersample(int x, int y, RayCounters& counters) const {
    const int spp = scene_.image.samples_per_pixel;
    glm::vec3 sum(0.0f);
    for (int k = 0; k < spp; ++k) {
      const Ray ray =
          sample_ray(x, y, image_sample(scene_.camera, options_.seed, k, spp, thin_lens_));
      PixelRng rng(options_.seed, x, y, k);
      counters.primary++;
      sum += trace(ray, 0, counters, &rng, textured_footprint());
    }
    return sum / float(spp);
  }

  // The ray of one sample of pixel (x, y). With a lens, its origin is the sample's point on the
  // lens disk, aimed at the point the pinhole ray meets at the focus distance (a thin lens:
  // every ray through one image point meets there). The direction keeps forward component 1, so
  // t stays view depth and near/far clip as before.
  Ray sample_ray(int x, int y, const ImageSample& sample) const {
    Ray r;
    r.origin = frame_.eye;
    r.dir = camera_ray_direction(frame_, float(x) + sample.jx, float(y) + sample.jy);
    // t along a direction with forward component 1 is view depth: clip exactly as GL does.
    r.tmin = scene_.camera.near;
    r.tmax = scene_.camera.far;
    if (!thin_lens_) return r;
    const glm::vec3 lens = frame_.eye + sample.lens_x * frame_.right + sample.lens_y * frame_.up;
    const glm::vec3 focus = frame_.eye + scene_.camera.focus_distance * r.dir;
    r.origin = lens;
    r.dir = (focus - lens) / scene_.camera.focus_distance;
    return r;
  }

  glm::vec3 trace(const Ray& ray, int depth, RayCounters& counters, PixelRng* rng,
                  const RayFootprint* footprint) const {
    HitRecord hit;
    if (!geometry_.closest(ray, hit, counters.traversal)) return scene_.image.background;
    return shade_hit(ray, hit, depth, counters, rng, footprint);
  }

  // The colour a ray brings back from its closest hit (primitive kNoPrimitive: it missed).
  // given_lod: as in shade().
  glm::vec3 shade_hit(const Ray& ray, const HitRecord& hit, int depth, RayCounters& counters,
                      PixelRng* rng, const RayFootprint* footprint,
                      const float* given_lod = nullptr) const {
    if (hit.primitive == kNoPrimitive) return scene_.image.background;
    SurfaceHit s = geometry_.surface(ray, hit);
    glm::vec3 V = -glm::normalize(ray.dir);
    return shade(ray, s, face_viewer(s.shading_normal, s.geometric_normal, V), V, depth, counters,
                 rng, footprint, nullptr, given_lod);
  }

  // The primary rays' footprint when the scene has a texture to sample, else null (no ray
  // carries one). Every primary ray carries the pixel-centre ray's: a jittered sample's direction
  // has the same derivatives along the pixel grid (it is linear in the image position); a lens
  // sample's is the pinhole's, an approximation.
  const RayFootprint* textured_footprint() const {
    return textured_ ? &primary_footprint_ : nullptr;
  }

  // The texture's level of detail at a hit on `triangle` of textured object o, for a ray of
  // direction D with `footprint`, hitting at t.
  float textured_hit_lod(const Object& o, uint32_t triangle, const glm::vec3& D, float t,
                         const RayFootprint& footprint) const {
    const TriangleMesh& mesh = o.mesh;
    const glm::uvec3 c = mesh.triangles[triangle];
    const glm::vec3 N = glm::normalize(glm::cross(mesh.positions[c.y] - mesh.positions[c.x],
                                                  mesh.positions[c.z] - mesh.positions[c.x]));
    const Material& m = scene_.materials[o.material];
    const MipChain& mips = *scene_.textures[size_t(m.texture)].mips;
    return texture_lod_at_hit(options_.texture_lod, footprint_at_hit(footprint, D, t, N), D, N,
                              mesh, m, triangle, mips.width(), mips.height());
  }

  // The base colour at barycentrics (u, v) of `triangle` of object o, whose colour varies
  // (varies_in_colour), and in lod the texture's level of detail there (NaN: not textured):
  // `given` when not null (a PrimaryHitSource's, for its primary hit), else the footprint's.
  glm::vec3 varying_base_colour(const Object& o, uint32_t triangle, float u, float v,
                                const glm::vec3& D, float t, const RayFootprint* footprint,
                                float& lod, const float* given = nullptr) const {
    lod = kNoLod;
    if (given)
      lod = *given;
    else if (footprint && textured(scene_, o))
      lod = textured_hit_lod(o, triangle, D, t, *footprint);
    return base_colour(scene_, o, scene_.materials[o.material], triangle, u, v, lod);
  }

  // rng is the pixel's stream when it takes several samples (area lights are then jittered
  // inside their strata), null for one sample at the pixel centre. footprint: the ray's, when
  // the scene has a texture; lod, when not null, receives the texture's level of detail at s;
  // given_lod, when not null, is the level to sample at s (a PrimaryHitSource's, for its hit).
  glm::vec3 shade(const Ray& ray, const SurfaceHit& s, const glm::vec3& N, const glm::vec3& V,
                  int depth, RayCounters& counters, PixelRng* rng, const RayFootprint* footprint,
                  float* lod, const float* given_lod = nullptr) const {
    std::optional<Material> coloured;  // the material with the base colour at s, where it varies
    if (varies_ && object_varies_[s.object]) {
      float hit_lod;
      coloured.emplace(
          with_diffuse(scene_.materials[s.material],
                       varying_base_colour(scene_.objects[s.object], s.primitive, s.u, s.v, ray.dir,
                                           s.t, footprint, hit_lod, given_lod)));
      if (lod) *lod = hit_lod;
    }
    const Material& m = coloured ? *coloured : scene_.materials[s.material];
    if (options_.mode != RenderMode::Full) {
      return shade_local(m, s.position, N, V, scene_.ambient, lights_);
    }
    float eps = ray_epsilon(s.position);
    glm::vec3 above = s.position + eps * N;  // on the viewer's side of the surface
    auto visibility = [&](size_t, const glm::vec3&, const glm::vec3& light) {
      return shadow_visibility(above, light, counters);
    };
    glm::vec3 local = shade_local(
        m, s.position, N, V, scene_.ambient,
        rng ? light_samples(scene_.lights, [rng] { return rng->uniform(); }) : lights_, visibility);
    glm::vec3 colour = (1.0f - m.mirror - m.transparency) * local;
    if (depth >= options_.max_depth) return colour;
    glm::vec3 d = glm::normalize(ray.dir);
    // The footprint where this ray meets s, for the rays that leave it (computed only for
    // those, and only when rays carry footprints).
    auto here = [&] { return footprint_at_hit(*footprint, ray.dir, s.t, s.geometric_normal); };
    if (m.mirror > 0.0f) {
      counters.reflection++;
      Ray r{above, glm::reflect(d, N), 0.0f, INFINITY};
      RayFootprint reflected;
      if (footprint) reflected = reflected_footprint(here(), N);
      colour += m.mirror * trace(r, depth + 1, counters, rng, footprint ? &reflected : nullptr);
    }
    if (m.transparency > 0.0f) {
      glm::vec3 below = s.position - eps * N;
      // Entering when the ray meets the outside of the surface as modelled.
      bool entering = glm::dot(s.geometric_normal, d) < 0.0f;
      float eta = entering ? 1.0f / m.ior : m.ior;
      float cos_i = -glm::dot(d, N);
      float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
      Ray r;
      RayFootprint leaving;
      if (k < 0.0f) {  // total internal reflection
        counters.reflection++;
        r = {above, glm::reflect(d, N), 0.0f, INFINITY};
        if (footprint) leaving = reflected_footprint(here(), N);
      } else {
        counters.refraction++;
        r = {below, eta * d + (eta * cos_i - std::sqrt(k)) * N, 0.0f, INFINITY};
        if (footprint) leaving = refracted_footprint(here(), d, N, eta);
      }
      colour += m.transparency * trace(r, depth + 1, counters, rng, footprint ? &leaving : nullptr);
    }
    return colour;
  }

  const Scene& scene_;
  const RenderOptions& options_;
  const TraceGeometry& geometry_;
  std::vector<LightSample> lights_;
  CameraFrame frame_;
  PrimaryRays rays_;
  const bool thin_lens_;  // full mode with an aperture: samples look through the lens
  bool centre_only_ = false;
  const ShadeKernels& kernels_;
  std::vector<ShadeMaterial> materials_;  // scene_.materials as the kernels read them
  ShadeLightArrays light_arrays_;         // lights_ likewise
  // Colour that varies over a surface (textures, vertex colours): per object, and whether any.
  std::vector<uint8_t> object_varies_, object_textured_;
  bool varies_ = false;
  bool textured_ = false;  // a texture to sample: rays carry footprints, the lod AOV is written
  RayFootprint primary_footprint_;
  // The pixels whose centre rays may meet anything (screen_bounds of the scene's bounds).
  PixelRect scene_rect_;
};

}  // namespace

Expected<RenderOutput> RayTracer::render(const Scene& scene, const RenderOptions& requested) {
  RenderOptions options = requested;
  if (has_forced_) options.accel = forced_;
  if (scene.image.width <= 0 || scene.image.height <= 0)
    return bad_input("image size must be positive");
  std::vector<std::string> notes;
  if (options.triangle_test == TriangleTest::Chapter && options.accel == AccelKind::Bvh) {
    // The SIMD kernels run Moller-Trumbore only; the chapter's test runs on the binary tree.
    options.accel = AccelKind::Bvh2;
    notes.push_back(
        "--triangle-test chapter runs on the binary BVH (bvh2): the wide BVH's "
        "SIMD kernels test triangles with Moller-Trumbore only");
  }

  auto t_build = Clock::now();
  if (ProgressSink* p = options.progress) p->begin("build");  // no count: time only
  TraceGeometry geometry(scene, options.spheres, options.sphere_segments, options.accel,
                         options.triangle_test, options.isa);
  double build_seconds = seconds_since(t_build);
  if (!geometry.error().empty()) return Error{geometry.error(), geometry.error_kind()};
  Expected<RenderOutput> out = render(scene, options, geometry);
  if (out.ok()) {
    out.value().stats["time.build"] = build_seconds;
    out.value().warnings.insert(out.value().warnings.begin(), notes.begin(), notes.end());
  }
  return out;
}

Expected<RenderOutput> RayTracer::render(const Scene& scene, const RenderOptions& options,
                                         const TraceGeometry& geometry) {
  return render_frame(scene, options, geometry, nullptr);
}

namespace {

// Runs tile(x0, y0, x1, y1, counters) over the image's tiles in parallel on `threads`
// (0: all), and returns the counters of every thread added up.
template <class Tile>
RayCounters for_each_tile(int w, int h, int threads, const Tile& tile) {
  tbb::combinable<RayCounters> counters;
  const int tiles_x = (w + kTileWidth - 1) / kTileWidth;
  const int tiles_y = (h + kTileHeight - 1) / kTileHeight;
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, tiles_x * tiles_y, 1),
        [&](const tbb::blocked_range<int>& range) {
          RayCounters& local = counters.local();
          for (int t = range.begin(); t != range.end(); ++t) {
            const int x0 = (t % tiles_x) * kTileWidth, y0 = (t / tiles_x) * kTileHeight;
            tile(x0, y0, std::min(x0 + kTileWidth, w), std::min(y0 + kTileHeight, h), local);
          }
        },
        tbb::simple_partitioner());
  });
  RayCounters total;
  counters.combine_each([&](const RayCounters& c) { total.add(c); });
  return total;
}

}  // namespace

Expected<RenderOutput> RayTracer::render(const Scene& scene, const RenderOptions& options,
                                         const TraceGeometry& geometry,
                                         const PrimaryHitSource& source) {
  return render_frame(scene, options, geometry, &source);
}

Expected<std::map<std::string, double>> RayTracer::add_samples(const Scene& scene,
                                                               const RenderOptions& options,
                                                               const TraceGeometry& geometry,
                                                               const PrimaryHitSource& source,
                                                               int k, std::span<glm::vec3> sum) {
  const int w = scene.image.width, h = scene.image.height;
  const int spp = scene.image.samples_per_pixel;
  if (w <= 0 || h <= 0 || sum.size() != size_t(w) * size_t(h) || k < 0 || k >= spp)
    return Error{"sample " + std::to_string(k) + " of " + std::to_string(spp) + " into " +
                     std::to_string(sum.size()) + " pixels",
                 ErrorKind::Internal};
  RenderOptions resolved = options;
  resolved.accel = geometry.accel();
  RVR_TRY_ASSIGN(isa, resolve_isa(options.isa));
  FrameTracer tracer(scene, resolved, geometry, shade_kernels(*isa));
  const ImageSample sample =
      image_sample(scene.camera, options.seed, k, spp, options.mode == RenderMode::Full);
  const RayCounters total =
      for_each_tile(w, h, options.threads, [&](int x0, int y0, int x1, int y1, RayCounters& c) {
        for (int by = y0; by < y1; by += kPacketSide)
          for (int bx = x0; bx < x1; bx += kPacketSide)
            tracer.add_sample_block(bx, by, std::min(bx + kPacketSide, x1),
                                    std::min(by + kPacketSide, y1), source, k, sample, sum.data(),
                                    c);
      });
  std::map<std::string, double> stats;
  total.report(stats, /*own_traversal=*/resolved.accel != AccelKind::Embree);
  return stats;
}

Expected<RenderOutput> RayTracer::render_frame(const Scene& scene, const RenderOptions& requested,
                                               const TraceGeometry& geometry,
                                               const PrimaryHitSource* source) {
  RenderOptions options = requested;
  options.accel = geometry.accel();
  RenderOutput out;
  const int w = scene.image.width, h = scene.image.height;
  if (w <= 0 || h <= 0) return bad_input("image size must be positive");

  // The shading kernels: chosen as the wide BVH's kernels are.
  RVR_TRY_ASSIGN(isa, resolve_isa(options.isa));
  auto t_render = Clock::now();
  out.buffers.allocate(w, h);  // every pixel is written below, in parallel
  if (std::any_of(scene.objects.begin(), scene.objects.end(),
                  [&](const Object& o) { return textured(scene, o); })) {
    out.buffers.lod.resize(out.buffers.pixel_count());
    out.info["texture_lod"] = options.texture_lod == TextureLod::Cones           ? "cones"
                              : options.texture_lod == TextureLod::Differentials ? "differentials"
                                                                                 : "none";
  }
  FrameTracer tracer(scene, options, geometry, shade_kernels(*isa));
  if (source) tracer.keep_centre_colour();
  // The fraction in pixels (known up front), the speed in rays of every kind (known as they go).
  ProgressSink* const progress = options.progress;
  if (progress) progress->begin("trace", uint64_t(w) * uint64_t(h), "pixels", "rays");
  const RayCounters total =
      for_each_tile(w, h, options.threads, [&](int x0, int y0, int x1, int y1, RayCounters& local) {
        if (is_cancelled(progress)) return;  // the tiles left are skipped
        const uint64_t t_tile = cycle_ticks();
        const uint64_t rays_before = local.rays();
        TileOutput tile;
        tile.begin(x0, y0, x1, y1);
        for (int by = y0; by < y1; by += kPacketSide)
          for (int bx = x0; bx < x1; bx += kPacketSide) {
            int bx1 = std::min(bx + kPacketSide, x1), by1 = std::min(by + kPacketSide, y1);
            if (source)
              tracer.render_block_from(bx, by, bx1, by1, *source, tile, local);
            else
              tracer.render_block(bx, by, bx1, by1, tile, local);
          }
        tile.write_to(out.buffers);
        if (progress)
          progress->advance(uint64_t(x1 - x0) * uint64_t(y1 - y0), local.rays() - rays_before);
        local.busy_ticks += cycle_ticks() - t_tile;
      });
  if (is_cancelled(progress)) return cancelled_error();
  const double render_seconds = seconds_since(t_render);
  out.stats["time.render"] = render_seconds;
  // The frame's time divided as the threads' time divides: until the primary hits are known
  // (rays generated and traced, or found by the PrimaryHitSource) and after (surfaces, AOVs,
  // shading and every ray after the primary hit).
  const double shade_share =
      total.busy_ticks > 0 ? double(total.shade_ticks) / double(total.busy_ticks) : 0;
  out.stats["time.shade"] = render_seconds * shade_share;
  out.stats["time.visibility"] = render_seconds - out.stats["time.shade"];
  out.info["shade_kernel"] = shade_kernels(*isa).isa;

  total.report(out.stats, options.accel != AccelKind::Embree);
  if (options.accel == AccelKind::Embree)  // Embree does not count its traversal steps
    out.warnings.push_back("embree does not report traversal work: the cost AOV is 0");
  out.stats["primitives"] = double(geometry.primitive_count());
  out.stats["triangles"] = double(geometry.triangle_count());
  out.info["accel"] = to_string(options.accel);
  if (options.accel == AccelKind::Bvh) {
    const WideBvhStats& w = geometry.wide_bvh().stats();
    out.info["kernel"] = geometry.kernel_isa();
    out.stats["bvh.width"] = double(kWideBvhWidth);
    out.stats["bvh.nodes"] = double(w.nodes + geometry.bvh().stats().nodes);
    out.stats["bvh.leaves"] = double(w.leaves + geometry.bvh().stats().leaves);
    out.stats["bvh.triangle_blocks"] = double(w.blocks);
    out.stats["bvh.block_fill"] = w.blocks ? double(w.triangles) / double(4 * w.blocks) : 0.0;
    out.stats["bvh.node_fill"] = w.nodes ? double(w.child_slots) / double(8 * w.nodes) : 0.0;
    out.stats["bvh.max_depth"] = double(w.max_depth);
    out.stats["bvh.bytes"] = double(geometry.acceleration_bytes());
    out.stats["time.bvh_build"] = w.seconds + geometry.bvh().stats().seconds;
  } else if (options.accel == AccelKind::Bvh2) {
    const BvhBuildStats& b = geometry.bvh().stats();
    out.stats["bvh.width"] = 2.0;
    out.stats["bvh.nodes"] = double(b.nodes);
    out.stats["bvh.leaves"] = double(b.leaves);
    out.stats["bvh.max_depth"] = double(b.max_depth);
    out.stats["bvh.sah_cost"] = b.sah_cost;
    out.stats["bvh.bytes"] = double(geometry.acceleration_bytes());
    out.stats["time.bvh_build"] = b.seconds;
  } else if (options.accel == AccelKind::Embree) {
    out.stats["bvh.bytes"] = double(geometry.acceleration_bytes());
  }
  if (options.mode == RenderMode::Full && scene.camera.aperture_radius > 0.0f &&
      scene.image.samples_per_pixel == 1) {
    out.warnings.push_back(kDepthOfFieldNeedsSamples);
  }
  return out;
}

std::string tbb_version() {
  return std::string(TBB_VERSION_STRING) + " (runtime " + TBB_runtime_version() + ")";
}

}  // namespace rvr
