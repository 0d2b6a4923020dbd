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
#include <utility>
#include <variant>
#include <vector>

#include "ray_counters.h"
#include "ray_footprint.h"
#include "rvr/core/camera.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/progress.h"
#include "rvr/core/shade_batch.h"
#include "rvr/core/shade_kernel.h"
#include "rvr/core/shading.h"
#include "rvr/core/surface_colour.h"
#include "rvr/core/texture.h"
#include "rvr/core/timer.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/intersect.h"
#include "rvr/raytrace/primary_rays.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh.h"
#include "rvr/raytrace/wide_bvh_layout.h"
#include "screen_bounds.h"
#include "tile_output.h"

namespace rvr {
namespace {

// Tiles run in parallel, each staged in a TileOutput: wide and short, so that each writes long
// runs of every buffer's rows.
constexpr int kTileWidth = TileOutput::kMaxWidth, kTileHeight = TileOutput::kMaxHeight;
// Primary rays go as packets of kPacketSide x kPacketSide pixel-centre rays (kPacketRays).
constexpr int kPacketSide = 8;
static_assert(kPacketSide * kPacketSide == kPacketRays);
// render_visible: a block with at least this many pixels to trace traces them as one packet.
constexpr int kPacketFallbacks = 8;

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
  // so the hybrid can trace sample k of every pixel in its own pass and draw the same numbers.
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

// The lod AOV where the visible surface is not textured.
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
        primary_footprint_(rvr::primary_footprint(frame_)) {
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

  // render_visible for the hybrid's accumulation-buffer passes: the pixel-centre pass keeps the
  // centre's colour; the passes add the samples (add_visible_sample).
  void keep_centre_colour() { centre_only_ = true; }

  // render_block_visible: pixels a z-buffer may leave empty where the scene is not (1 inside the
  // screen bounds of the shapes it draws approximately or not at all), row-major; null: none.
  void set_approximated_mask(const uint8_t* mask) { approximated_mask_ = mask; }

  // Sample k of each pixel of [x0, x1) x [y0, y1): its ray intersected with the primitive that
  // `visible` (a z-buffer drawn through image_sample k) names there, else traced; the CSG
  // objects intersected besides, as in render_block_visible. Its colour is added to sum.
  void sample_block_visible(int x0, int y0, int x1, int y1, const PrimaryVisibility& visible, int k,
                            const ImageSample& sample, glm::vec3* sum,
                            RayCounters& counters) const {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const size_t i = size_t(y) * size_t(visible.width) + size_t(x);
        const Ray ray = sample_ray(x, y, sample);
        PixelRng rng(options_.seed, x, y, k);
        counters.primary++;
        HitRecord hit;
        const bool rebuilt =
            visible.object_id[i] != kNoId &&
            geometry_.intersect_visible(ray, visible.object_id[i], visible.primitive_id[i], hit,
                                        counters.traversal);
        // A hit rebuilt from the z-buffer samples its texture at the z-buffer's level.
        const float* given_lod = rebuilt && !visible.lod.empty() ? &visible.lod[i] : nullptr;
        if (rebuilt) {
          counters.rebuilt++;
          HitRecord csg;
          if (geometry_.has_csg() && geometry_.closest_csg(ray, csg, counters.traversal) &&
              (csg.t < hit.t || (csg.t == hit.t && csg.primitive < hit.primitive))) {
            hit = csg;
            given_lod = nullptr;
            counters.csg_pixels++;
          }
        } else {
          counters.fallback_traced++;
          counters.fallback_missed += visible.object_id[i] != kNoId;
          if (!geometry_.closest(ray, hit, counters.traversal)) hit = HitRecord{};
        }
        sum[i] += shade_hit(ray, hit, 0, counters, &rng, textured_footprint(), given_lod);
      }
  }

  // The pixels [x0, x1) x [y0, y1) of one tile (at most kPacketSide on a side): their centre
  // rays traced together as one packet, then finished (finish_block).
  void render_block(int x0, int y0, int x1, int y1, TileOutput& out, RayCounters& counters) const {
    const RayPacket packet = rays_.packet(x0, y0, x1 - x0, y1 - y0);
    HitRecord hits[kPacketRays];
    TraversalCounters work[kPacketRays];
    geometry_.closest_packet(packet, hits, work);
    counters.primary += uint64_t(packet.count);
    finish_block(x0, y0, x1 - x0, packet, hits, work, out, counters);
  }

  // The same pixels with their primary hits rebuilt from `visible`'s ids (render_visible).
  void render_block_visible(int x0, int y0, int x1, int y1, const PrimaryVisibility& visible,
                            TileOutput& out, RayCounters& counters) const {
    if (shows_only_background(x0, y0, x1, y1, visible)) {
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          out.set_background(out.index(x, y), scene_.image.background);
          if (textured_) out.lod[out.index(x, y)] = kNoLod;
        }
      counters.background += uint64_t(x1 - x0) * uint64_t(y1 - y0);
      return;
    }
    const int w = x1 - x0;
    // The very rays render_block traces.
    const RayPacket packet = rays_.packet(x0, y0, w, y1 - y0);
    const int n = packet.count;
    HitRecord hits[kPacketRays];
    TraversalCounters work[kPacketRays];
    bool traced[kPacketRays];
    int n_traced = 0;
    const uint64_t background_before = counters.background;
    // The ids the z-buffer drew, and which pixels need a ray at all.
    uint32_t object[kPacketRays], primitive[kPacketRays];
    bool drawn[kPacketRays], rebuilt[kPacketRays];
    // The z-buffer's texture level of detail, taken by the hits rebuilt from it (given).
    float zbuffer_lod[kPacketRays];
    bool given[kPacketRays];
    for (int y = y0, k = 0; y < y1; ++y)
      for (int x = x0; x < x1; ++x, ++k) {  // ray k is pixel (x, y)
        const size_t i = size_t(y) * size_t(visible.width) + size_t(x);
        given[k] = false;
        zbuffer_lod[k] = visible.lod.empty() ? kNoLod : visible.lod[i];
        object[k] = visible.object_id[i];
        primitive[k] = visible.primitive_id[i];
        drawn[k] = object[k] != kNoId;
        hits[k] = HitRecord{};
        work[k] = TraversalCounters{};
        traced[k] = !drawn[k] && may_hide_a_surface(x, y, visible);
        // Otherwise background to the z-buffer, away from every edge it drew and from every
        // shape it could not draw exactly: background to the tracer too, without a ray.
        if (!drawn[k] && !traced[k]) counters.background++;
      }
    geometry_.intersect_visible_packet(packet, object, primitive, drawn, hits, rebuilt, work);
    for (int k = 0; k < n; ++k) {
      if (!drawn[k]) {
        n_traced += traced[k];
        continue;
      }
      if (!rebuilt[k]) {
        // The z-buffer's polygon covers the centre where the exact surface does not
        // (silhouettes, shared edges): the tracer decides, below.
        traced[k] = true;
        n_traced++;
        counters.fallback_missed++;
        continue;
      }
      counters.rebuilt++;
      given[k] = !visible.lod.empty();
      if (geometry_.has_csg()) {
        // No z-buffer draws CSG: the ray meets the CSG objects alone; the nearer hit wins, ties
        // by primitive index as in closest().
        HitRecord csg;
        if (geometry_.closest_csg(PrimaryRays::ray_of(packet, k), csg, work[k]) &&
            (csg.t < hits[k].t || (csg.t == hits[k].t && csg.primitive < hits[k].primitive))) {
          hits[k] = csg;
          given[k] = false;
          counters.csg_pixels++;
        }
      }
    }
    counters.fallback_traced += uint64_t(n_traced);
    if (n_traced >= kPacketFallbacks) {
      // Many to trace (an empty background): the whole block as one packet, as render_block
      // traces it; its hits are closest()'s, so which way is taken changes no pixel.
      HitRecord packet_hits[kPacketRays];
      TraversalCounters packet_work[kPacketRays];
      geometry_.closest_packet(packet, packet_hits, packet_work);
      for (int k = 0; k < n; ++k) {
        if (traced[k]) {
          hits[k] = packet_hits[k];
          work[k] = packet_work[k];
        } else {  // traversed for nothing, but traversed: counted, not charged to the pixel
          counters.traversal.nodes_visited += packet_work[k].nodes_visited;
          counters.traversal.primitive_tests += packet_work[k].primitive_tests;
        }
      }
    } else if (n_traced > 0) {
      for (int k = 0; k < n; ++k) {
        if (!traced[k]) continue;
        hits[k] = HitRecord{};
        geometry_.closest(PrimaryRays::ray_of(packet, k), hits[k], work[k]);
      }
    }
    if (geometry_.has_csg())
      for (int k = 0; k < n; ++k)
        if (traced[k] && hits[k].primitive != kNoPrimitive &&
            scene_.objects[geometry_.hit_ids(hits[k]).first].type == ObjectType::Csg)
          counters.csg_pixels++;
    counters.primary += uint64_t(n) - (counters.background - background_before);
    finish_block(x0, y0, w, packet, hits, work, out, counters, zbuffer_lod, given);
  }

 private:
  // Whether no pixel of [x0, x1) x [y0, y1) can show anything to the tracer: the z-buffer
  // covered none of them nor of their neighbours, and none lies where a shape it draws
  // approximately or not at all may appear (may_hide_a_surface for the whole block at once).
  bool shows_only_background(int x0, int y0, int x1, int y1,
                             const PrimaryVisibility& visible) const {
    const size_t width = size_t(visible.width);
    if (approximated_mask_)
      for (int y = y0; y < y1; ++y) {
        const uint8_t* row = approximated_mask_ + size_t(y) * width;
        for (int x = x0; x < x1; ++x)
          if (row[x]) return false;
      }
    const int nx0 = std::max(x0 - 1, 0), nx1 = std::min(x1 + 1, visible.width);
    for (int y = std::max(y0 - 1, 0); y < std::min(y1 + 1, visible.height); ++y) {
      const uint32_t* row = visible.object_id.data() + size_t(y) * width;
      uint32_t all = ~0u;  // kNoId where every id is kNoId
      for (int x = nx0; x < nx1; ++x) all &= row[x];
      if (all != kNoId) return false;
    }
    return true;
  }

  // Whether the tracer may see a surface at empty pixel (x, y) of a z-buffer's ids: next to a
  // pixel it covered (a silhouette or shared edge may fall either way at a centre), or where a
  // shape it draws approximately or not at all may appear.
  bool may_hide_a_surface(int x, int y, const PrimaryVisibility& visible) const {
    const size_t width = size_t(visible.width);
    if (approximated_mask_ && approximated_mask_[size_t(y) * width + size_t(x)]) return true;
    for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, visible.height - 1); ++ny)
      for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, visible.width - 1); ++nx)
        if (visible.object_id[size_t(ny) * width + size_t(nx)] != kNoId) return true;
    return false;
  }

  // The pixels of one block once the closest hits of their centre rays are known: hits[k] (for
  // ray k of `packet`, row by row, w wide; primitive kNoPrimitive where it missed), found with
  // work[k]. Every buffer of every pixel is written into `out`: the AOVs from the centre hit; in
  // local mode the surface and colour computed by the shading kernels, the block's hits as one
  // batch; in full mode (shadow, reflection and refraction rays) one pixel at a time.
  // given_lod[k], where given[k] (both may be null: none), is the texture level of detail ray
  // k's hit samples at instead of its own footprint's (a hybrid's z-buffer's).
  void finish_block(int x0, int y0, int w, const RayPacket& packet, const HitRecord* hits,
                    const TraversalCounters* work, TileOutput& out, RayCounters& counters,
                    const float* given_lod = nullptr, const bool* given = nullptr) const {
    static_assert(kPacketRays <= kShadeBatch, "a block's hits fit one batch");
    const auto start = Clock::now();
    const RenderMode mode = options_.mode;
    const bool supersampled =
        mode != RenderMode::Visibility && scene_.image.samples_per_pixel > 1 && !centre_only_;
    SurfaceBatch batch;
    for (int a = 0; a < 3; ++a) batch.origin[a] = packet.origin[a];
    size_t batch_pixel[kPacketRays];
    bool mixed = false;  // the batch's pixels have more than one material
    uint32_t batch_material = 0;
    const int y1 = y0 + packet.count / w;
    for (int y = y0, k = 0; y < y1; ++y)
      for (int x = x0; x < x0 + w; ++x, ++k) {  // ray k is pixel (x, y)
        const size_t i = out.index(x, y);
        const HitRecord& hit = hits[k];
        counters.traversal.nodes_visited += work[k].nodes_visited;
        counters.traversal.primitive_tests += work[k].primitive_tests;
        const uint64_t work_before =
            counters.traversal.nodes_visited + counters.traversal.primitive_tests;
        if (textured_) out.lod[i] = kNoLod;
        if (hit.primitive == kNoPrimitive) {
          out.set_background(i, scene_.image.background);
        } else if (mode == RenderMode::Visibility) {
          // Visibility is the hit's distance and ids: no surface, no shading.
          const auto [object, primitive] = geometry_.hit_ids(hit);
          out.colour[i] = scene_.image.background;
          out.depth[i] = hit.t;  // the direction's forward component is 1: t is view depth
          out.object_id[i] = object;
          out.primitive_id[i] = primitive;
          out.normal[i] = glm::vec3(0.0f);
          if (textured_ && object_textured_[object]) {
            const glm::vec3 D(packet.dir[0][k], packet.dir[1][k], packet.dir[2][k]);
            out.lod[i] = given && given[k] ? given_lod[k]
                                           : textured_hit_lod(scene_.objects[object], primitive, D,
                                                              hit.t, primary_footprint_);
          }
        } else if (mode == RenderMode::Local) {
          const int slot = batch.count++;
          batch_pixel[slot] = i;
          const uint32_t material = add_to_batch(batch, slot, packet, k, hit, out, i);
          const uint32_t object = out.object_id[i];
          if (varies_ && object_varies_[object]) {
            // Its own material: the diffuse replaced by the base colour at the hit.
            const glm::vec3 D(packet.dir[0][k], packet.dir[1][k], packet.dir[2][k]);
            const Material& m = scene_.materials[material];
            const glm::vec3 base = varying_base_colour(
                scene_.objects[object], out.primitive_id[i], hit.u, hit.v, D, hit.t,
                &primary_footprint_, out.lod[i], given && given[k] ? &given_lod[k] : nullptr);
            if (!mixed) {
              mixed = true;
              for (int j = 0; j < slot; ++j) put_material(batch, j, materials_[batch_material]);
            }
            put_material(batch, slot, shade_material(with_diffuse(m, base), scene_.ambient));
          } else {
            if (slot == 0) {
              batch_material = material;
            } else if (!mixed && material != batch_material) {
              mixed = true;  // from now on each slot carries its material
              for (int j = 0; j < slot; ++j) put_material(batch, j, materials_[batch_material]);
            }
            if (mixed) put_material(batch, slot, materials_[material]);
          }
        } else {
          const Ray ray = PrimaryRays::ray_of(packet, k);
          const SurfaceHit s = geometry_.surface(ray, hit);
          const glm::vec3 V = -glm::normalize(ray.dir);
          const glm::vec3 N = face_viewer(s.shading_normal, s.geometric_normal, V);
          out.depth[i] = s.t;
          out.object_id[i] = s.object;
          out.primitive_id[i] = s.primitive;
          out.normal[i] = N;
          out.colour[i] =
              shade(ray, s, N, V, 0, counters, nullptr, textured_footprint(),
                    textured_ ? &out.lod[i] : nullptr, given && given[k] ? &given_lod[k] : nullptr);
        }
        if (supersampled) out.colour[i] = supersample(x, y, counters);
        // Work for this pixel: its centre ray and every ray its shading traced.
        out.cost[i] = options_.cost_aov ? float(work[k].nodes_visited + work[k].primitive_tests +
                                                counters.traversal.nodes_visited +
                                                counters.traversal.primitive_tests - work_before)
                                        : 0.0f;
      }
    if (batch.count > 0) {
      pad_batch(batch, mixed);
      batch.material = mixed ? nullptr : &materials_[batch_material];
      kernels_.shade_surfaces(batch, light_arrays_.lights());
      for (int slot = 0; slot < batch.count; ++slot) {
        const size_t i = batch_pixel[slot];
        out.normal[i] = {batch.shading_normal[0][slot], batch.shading_normal[1][slot],
                         batch.shading_normal[2][slot]};
        if (!supersampled)
          out.colour[i] = {batch.colour[0][slot], batch.colour[1][slot], batch.colour[2][slot]};
      }
    }
    counters.shade_seconds += seconds_since(start);
  }

  // Puts ray k's hit into slot `slot` of the batch, for the kernel to compute its surface, and
  // its depth and ids into pixel i of `out`; returns its material. Every input of the slot is
  // written (zeros where the kernel selects it away), so no lane reads undefined memory.
  uint32_t add_to_batch(SurfaceBatch& batch, int slot, const RayPacket& packet, int k,
                        const HitRecord& hit, TileOutput& out, size_t i) const {
    const glm::vec3 zero(0.0f);
    batch.t[slot] = hit.t;
    for (int a = 0; a < 3; ++a) batch.direction[a][slot] = packet.dir[a][k];
    out.depth[i] = hit.t;  // the direction's forward component is 1: t is view depth
    if (hit.primitive < geometry_.triangle_count()) {
      const TriangleSurfaceData d = geometry_.triangle_surface_data(hit.primitive);
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
  // `given` when not null (a hybrid's primary hit takes its z-buffer's), else the footprint's.
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
  // given_lod, when not null, is the level to sample at s (a z-buffer's, for a hybrid's hit).
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
      Ray shadow{above, light - above, 0.0f, 1.0f - 1e-4f};
      counters.shadow++;
      return geometry_.occluded(shadow, counters.traversal) ? 0.0f : 1.0f;
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
  const uint8_t* approximated_mask_ = nullptr;
  std::vector<ShadeMaterial> materials_;  // scene_.materials as the kernels read them
  ShadeLightArrays light_arrays_;         // lights_ likewise
  // Colour that varies over a surface (textures, vertex colours): per object, and whether any.
  std::vector<uint8_t> object_varies_, object_textured_;
  bool varies_ = false;
  bool textured_ = false;  // a texture to sample: rays carry footprints, the lod AOV is written
  RayFootprint primary_footprint_;
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
  return render_frame(scene, options, geometry, nullptr, false);
}

namespace {

std::optional<Error> check_visibility_size(const Scene& scene, const PrimaryVisibility& visible) {
  const size_t n = size_t(std::max(scene.image.width, 0)) * size_t(std::max(scene.image.height, 0));
  if (visible.width != scene.image.width || visible.height != scene.image.height ||
      visible.object_id.size() != n || visible.primitive_id.size() != n)
    return Error{"visibility buffer is " + std::to_string(visible.width) + "x" +
                     std::to_string(visible.height) + ", the image " +
                     std::to_string(scene.image.width) + "x" + std::to_string(scene.image.height),
                 ErrorKind::Internal};
  return std::nullopt;
}

// 1 at the pixels inside the screen bounds of a shape that a z-buffer draws approximately or not
// at all (TraceGeometry::approximated_bounds), row-major.
std::vector<uint8_t> approximated_mask(const Scene& scene, const TraceGeometry& geometry) {
  const int w = scene.image.width, h = scene.image.height;
  const CameraFrame frame = make_camera_frame(scene.camera, w, h);
  std::vector<uint8_t> mask(size_t(w) * size_t(h), 0);
  for (const Aabb& box : geometry.approximated_bounds()) {
    const PixelRect r = screen_bounds(frame, scene.camera.near, box);
    for (int y = r.y0; y < r.y1; ++y)
      if (r.x1 > r.x0)
        std::memset(mask.data() + size_t(y) * size_t(w) + size_t(r.x0), 1, size_t(r.x1 - r.x0));
  }
  return mask;
}

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

Expected<RenderOutput> RayTracer::render_visible(const Scene& scene, const RenderOptions& options,
                                                 const TraceGeometry& geometry,
                                                 const PrimaryVisibility& visible,
                                                 VisibleSamples samples) {
  if (auto error = check_visibility_size(scene, visible)) return *error;
  return render_frame(scene, options, geometry, &visible, samples == VisibleSamples::FromPasses);
}

Expected<std::map<std::string, double>> RayTracer::add_visible_sample(
    const Scene& scene, const RenderOptions& options, const TraceGeometry& geometry,
    const PrimaryVisibility& visible, int k, std::span<glm::vec3> sum) {
  if (auto error = check_visibility_size(scene, visible)) return *error;
  const int w = scene.image.width, h = scene.image.height;
  const int spp = scene.image.samples_per_pixel;
  if (sum.size() != size_t(w) * size_t(h) || k < 0 || k >= spp)
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
        tracer.sample_block_visible(x0, y0, x1, y1, visible, k, sample, sum.data(), c);
      });
  std::map<std::string, double> stats;
  total.report(stats, /*visible=*/true, /*own_traversal=*/resolved.accel != AccelKind::Embree);
  return stats;
}

Expected<RenderOutput> RayTracer::render_frame(const Scene& scene, const RenderOptions& requested,
                                               const TraceGeometry& geometry,
                                               const PrimaryVisibility* visible, bool centre_only) {
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
  if (centre_only) tracer.keep_centre_colour();
  std::vector<uint8_t> approximated;
  if (visible) {
    approximated = approximated_mask(scene, geometry);
    tracer.set_approximated_mask(approximated.data());
  }
  // The fraction in pixels (known up front), the speed in rays of every kind (known as they go).
  ProgressSink* const progress = options.progress;
  if (progress) progress->begin("trace", uint64_t(w) * uint64_t(h), "pixels", "rays");
  const RayCounters total =
      for_each_tile(w, h, options.threads, [&](int x0, int y0, int x1, int y1, RayCounters& local) {
        if (is_cancelled(progress)) return;  // the tiles left are skipped
        const auto t_tile = Clock::now();
        const uint64_t rays_before = local.rays();
        TileOutput tile;
        tile.begin(x0, y0, x1, y1);
        for (int by = y0; by < y1; by += kPacketSide)
          for (int bx = x0; bx < x1; bx += kPacketSide) {
            int bx1 = std::min(bx + kPacketSide, x1), by1 = std::min(by + kPacketSide, y1);
            if (visible)
              tracer.render_block_visible(bx, by, bx1, by1, *visible, tile, local);
            else
              tracer.render_block(bx, by, bx1, by1, tile, local);
          }
        tile.write_to(out.buffers);
        if (progress)
          progress->advance(uint64_t(x1 - x0) * uint64_t(y1 - y0), local.rays() - rays_before);
        local.busy_seconds += seconds_since(t_tile);
      });
  if (is_cancelled(progress)) return cancelled_error();
  const double render_seconds = seconds_since(t_render);
  out.stats["time.render"] = render_seconds;
  // The frame's time divided as the threads' time divides: until the primary hits are known
  // (rays generated and traced, or rebuilt from the z-buffer's ids) and after (surfaces, AOVs,
  // shading and every ray after the primary hit).
  const double shade_share = total.busy_seconds > 0 ? total.shade_seconds / total.busy_seconds : 0;
  out.stats["time.shade"] = render_seconds * shade_share;
  out.stats["time.visibility"] = render_seconds - out.stats["time.shade"];
  out.info["shade_kernel"] = shade_kernels(*isa).isa;

  total.report(out.stats, visible != nullptr, options.accel != AccelKind::Embree);
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
  }
  if (options.mode == RenderMode::Full && scene.camera.aperture_radius > 0.0f &&
      scene.image.samples_per_pixel == 1) {
    out.warnings.push_back("depth of field needs samples_per_pixel > 1: one sample is a pinhole");
  }
  return out;
}

std::string tbb_version() {
  return std::string(TBB_VERSION_STRING) + " (runtime " + TBB_runtime_version() + ")";
}

}  // namespace rvr
