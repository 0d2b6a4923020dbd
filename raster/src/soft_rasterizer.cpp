#include "rvr/raster/soft_rasterizer.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "rvr/shared/camera.h"
#include "rvr/shared/shading.h"
#include "rvr/shared/tessellate.h"
#include "soft/tile_raster.h"
#include "soft/triangle_setup.h"

namespace rvr {

namespace {

using Clock = std::chrono::steady_clock;
using soft::DepthTarget;
using soft::ProjectedVertex;
using soft::SetupTriangle;
using soft::TileCounters;
using soft::TriangleSetup;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Triangles stream through in chunks of kChunk (in submission order), each set up by kSubChunk at
// a time in parallel, binned, and drawn into every tile before the next: memory holds one chunk,
// whatever the triangle count.
constexpr size_t kChunk = size_t(1) << 16;
constexpr size_t kSubChunk = 4096;

// What shading needs per object; tessellated shapes point into SoftRasterizer-owned meshes.
struct DrawObject {
  const TriangleMesh* mesh = nullptr;
  const Material* material = nullptr;
  bool smooth = false;
  bool use_primitive_id = false;
};

// A thread's setup state: its own clipping scratch and a cache of projected vertices (a mesh's
// neighbouring triangles share them, so most are projected once, not once per triangle).
struct SetupWorker {
  static constexpr size_t kCacheSize = 4096;
  explicit SetupWorker(const TriangleSetup& prototype)
      : setup(prototype), keys(kCacheSize, ~0ull), cache(kCacheSize) {}
  const ProjectedVertex& vertex(uint32_t object, uint32_t index, const glm::vec3& p) {
    const uint64_t key = uint64_t(object) << 32 | index;
    const size_t slot = (index ^ object * 0x9E3779B1u) & (kCacheSize - 1);
    if (keys[slot] != key) {
      keys[slot] = key;
      cache[slot] = setup.project(p);
    }
    return cache[slot];
  }
  TriangleSetup setup;
  std::vector<uint64_t> keys;
  std::vector<ProjectedVertex> cache;
};

std::string object_label(const Object& o, size_t index) {
  return o.name.empty() ? fmt::format("csg#{}", index) : o.name;
}

Expected<RenderOutput> render_impl(const Scene& scene, const RenderOptions& options) {
  const int w = scene.image.width, h = scene.image.height;
  if (w < 1 || h < 1) return bad_input(fmt::format("image size {}x{} is empty", w, h));
  if (w > soft::kMaxImageSide || h > soft::kMaxImageSide)
    return bad_input(fmt::format("image size {}x{}: softraster draws at most {} pixels a side", w,
                                 h, soft::kMaxImageSide));
  RenderOutput out;
  ProgressSink* const progress = options.progress;
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);

  // --- setup: objects to triangles, transform, clip, bin (in submission order)
  auto t = Clock::now();
  std::vector<TriangleMesh> tessellated;  // sphere and plane meshes, alive until shading ends
  tessellated.reserve(scene.objects.size());
  std::vector<DrawObject> objects(scene.objects.size());
  std::vector<std::string> skipped_csg;
  bool mirror = false, transparency = false;
  const Material fallback = default_material();
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const Object& o = scene.objects[i];
    DrawObject& d = objects[i];
    if (o.material < scene.materials.size()) {
      d.material = &scene.materials[o.material];
    } else if (scene.materials.empty()) {
      d.material = &fallback;  // a hand-made scene with no material list: the built-in grey
    } else {
      return bad_input(
          fmt::format("object '{}': material index {} out of range", o.name, o.material));
    }
    switch (o.type) {
      case ObjectType::Triangles:
        d.mesh = &o.mesh;
        d.use_primitive_id = true;
        break;
      case ObjectType::Sphere:
        tessellated.push_back(tessellate_sphere(o.sphere, options.sphere_segments));
        d.mesh = &tessellated.back();
        break;
      case ObjectType::Plane:
        tessellated.push_back(tessellate_plane(o.plane));
        d.mesh = &tessellated.back();
        break;
      case ObjectType::Csg:
        skipped_csg.push_back(object_label(o, i));
        continue;
    }
    const TriangleMesh& m = *d.mesh;
    d.smooth = m.smooth();
    if (m.smooth() && m.normals.size() != m.positions.size())
      return bad_input(fmt::format("object '{}': {} normals for {} positions", o.name,
                                   m.normals.size(), m.positions.size()));
    for (const glm::uvec3& tri : m.triangles)
      if (std::max({tri.x, tri.y, tri.z}) >= m.positions.size())
        return bad_input(fmt::format("object '{}': triangle index out of range ({} positions)",
                                     o.name, m.positions.size()));
    mirror |= d.material->mirror > 0.0f;
    transparency |= d.material->transparency > 0.0f;
  }

  const glm::dmat4 view_projection =
      glm::dmat4(projection_matrix(scene.camera, w, h)) * glm::dmat4(view_matrix(scene.camera));
  // Submission order: objects in turn, each mesh's triangles in turn.
  std::vector<size_t> object_first(objects.size() + 1, 0);
  for (size_t i = 0; i < objects.size(); ++i)
    object_first[i + 1] =
        object_first[i] + (objects[i].mesh ? objects[i].mesh->triangles.size() : 0);
  const size_t submitted = object_first.back();
  out.stats["time.setup"] = seconds_since(t);

  DepthTarget target(w, h, scene.camera.near, scene.camera.far, options.hiz);
  const size_t tile_count = size_t(target.tiles_x()) * size_t(target.tiles_y());
  const TriangleSetup prototype(w, h, view_projection);
  tbb::enumerable_thread_specific<SetupWorker> workers(prototype);
  std::vector<std::vector<SetupTriangle>> sub_out((kChunk + kSubChunk - 1) / kSubChunk);
  std::vector<size_t> sub_clipped(sub_out.size());
  std::vector<uint32_t> counts, bin_start(tile_count + 1), bin;
  std::vector<TileCounters> counters(tile_count);
  size_t clipped = 0, set_up = 0, peak_chunk_bytes = 0;
  double setup_seconds = 0, bin_seconds = 0, raster_seconds = 0;
  // The fraction in triangles, the speed in fragments.
  if (progress) progress->begin("draw", submitted, "triangles", "fragments");
  for (size_t chunk = 0; chunk < submitted; chunk += kChunk) {
    const size_t chunk_end = std::min(submitted, chunk + kChunk);
    const size_t subs = (chunk_end - chunk + kSubChunk - 1) / kSubChunk;
    // --- setup: transform, cull, clip; sub-chunks in parallel, joined in order
    t = Clock::now();
    arena.execute([&] {
      tbb::parallel_for(size_t(0), subs, [&](size_t s) {
        SetupWorker& worker = workers.local();
        std::vector<SetupTriangle>& local = sub_out[s];
        local.clear();
        local.reserve(kSubChunk);
        size_t local_clipped = 0;
        const size_t begin = chunk + s * kSubChunk, end = std::min(chunk_end, begin + kSubChunk);
        size_t object = size_t(std::upper_bound(object_first.begin(), object_first.end(), begin) -
                               object_first.begin()) -
                        1;
        for (size_t g = begin; g < end; ++g) {
          while (g >= object_first[object + 1]) ++object;
          const TriangleMesh& m = *objects[object].mesh;
          const uint32_t primitive = uint32_t(g - object_first[object]);
          const glm::uvec3& tri = m.triangles[primitive];
          const uint32_t o = uint32_t(object);
          // Copies: the next lookups may evict an entry.
          const ProjectedVertex a = worker.vertex(o, tri.x, m.positions[tri.x]);
          const ProjectedVertex b = worker.vertex(o, tri.y, m.positions[tri.y]);
          const ProjectedVertex c = worker.vertex(o, tri.z, m.positions[tri.z]);
          worker.setup.add(a, b, c, o, primitive, local, local_clipped);
        }
        sub_clipped[s] = local_clipped;
      });
    });
    for (size_t s = 0; s < subs; ++s) {
      clipped += sub_clipped[s];
      set_up += sub_out[s].size();
    }
    setup_seconds += seconds_since(t);

    // --- bin: a counting sort of the chunk's triangles into tiles, in submission order
    t = Clock::now();
    const int tiles_x = target.tiles_x();
    auto for_tiles = [&](const SetupTriangle& st, auto&& fn) {
      for (int ty = st.y0 / soft::kTile; ty <= st.y1 / soft::kTile; ++ty)
        for (int tx = st.x0 / soft::kTile; tx <= st.x1 / soft::kTile; ++tx)
          fn(size_t(ty) * size_t(tiles_x) + size_t(tx));
    };
    counts.assign(subs * tile_count, 0);
    arena.execute([&] {
      tbb::parallel_for(size_t(0), subs, [&](size_t s) {
        uint32_t* c = &counts[s * tile_count];
        for (const SetupTriangle& st : sub_out[s]) for_tiles(st, [&](size_t b) { ++c[b]; });
      });
    });
    // Offsets: tile by tile, and within a tile sub-chunk by sub-chunk (submission order).
    uint32_t running = 0;
    for (size_t b = 0; b < tile_count; ++b) {
      bin_start[b] = running;
      for (size_t s = 0; s < subs; ++s) {
        uint32_t n = counts[s * tile_count + b];
        counts[s * tile_count + b] = running;
        running += n;
      }
    }
    bin_start[tile_count] = running;
    bin.resize(running);
    arena.execute([&] {
      tbb::parallel_for(size_t(0), subs, [&](size_t s) {
        uint32_t* next = &counts[s * tile_count];
        const uint32_t tag = uint32_t(s) << DepthTarget::kLocalBits;
        for (size_t i = 0; i < sub_out[s].size(); ++i)
          for_tiles(sub_out[s][i], [&](size_t b) { bin[next[b]++] = tag | uint32_t(i); });
      });
    });
    bin_seconds += seconds_since(t);
    size_t chunk_bytes = (bin.capacity() + counts.capacity()) * sizeof(uint32_t);
    for (const auto& v : sub_out) chunk_bytes += v.capacity() * sizeof(SetupTriangle);
    peak_chunk_bytes = std::max(peak_chunk_bytes, chunk_bytes);

    // --- raster: tiles in parallel, each independent of the others
    t = Clock::now();
    std::atomic<uint64_t> fragments{0};
    arena.execute([&] {
      tbb::parallel_for(size_t(0), tile_count, [&](size_t b) {
        if (bin_start[b + 1] == bin_start[b]) return;
        const uint64_t before = counters[b].generated;
        target.draw_tile(int(b % size_t(tiles_x)), int(b / size_t(tiles_x)), sub_out.data(),
                         bin.data() + bin_start[b], bin_start[b + 1] - bin_start[b], counters[b]);
        fragments.fetch_add(counters[b].generated - before, std::memory_order_relaxed);
      });
    });
    raster_seconds += seconds_since(t);
    if (progress) progress->advance(chunk_end - chunk, fragments.load());
  }
  out.stats["time.setup"] += setup_seconds;
  out.stats["time.bin"] = bin_seconds;
  out.stats["time.raster"] = raster_seconds;

  // --- shade: deferred, each visible pixel once
  t = Clock::now();
  FrameBuffers& fb = out.buffers;
  fb.allocate(w, h);  // every pixel is written below
  const std::vector<LightSample> samples = options.mode == RenderMode::Visibility
                                               ? std::vector<LightSample>{}
                                               : light_samples(scene.lights);
  const glm::vec3 eye = scene.camera.eye;
  if (progress) progress->begin("shade", uint64_t(w) * uint64_t(h), "pixels");
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      for (int y = r.begin(); y != r.end(); ++y) {
        for (int x = 0; x < w; ++x) {
          const size_t o = fb.index(x, y);
          fb.set_background(o, scene.image.background);
          fb.cost[o] = target.cost(o);
          if (!target.covered(o)) continue;
          const DrawObject& d = objects[target.object(o)];
          const uint32_t primitive = target.primitive(o);
          const glm::vec3 b = target.barycentric(o);
          const glm::uvec3& tri = d.mesh->triangles[primitive];
          const glm::vec3 &p0 = d.mesh->positions[tri.x], &p1 = d.mesh->positions[tri.y],
                          &p2 = d.mesh->positions[tri.z];
          const glm::vec3 P = b.x * p0 + b.y * p1 + b.z * p2;
          const glm::vec3 g = glm::normalize(glm::cross(p1 - p0, p2 - p0));
          const glm::vec3 shading =
              d.smooth ? glm::normalize(b.x * d.mesh->normals[tri.x] +
                                        b.y * d.mesh->normals[tri.y] + b.z * d.mesh->normals[tri.z])
                       : g;
          const glm::vec3 V = glm::normalize(eye - P);
          const glm::vec3 N = face_viewer(shading, g, V);
          fb.depth[o] = float(target.depth(o));
          fb.object_id[o] = target.object(o);
          fb.primitive_id[o] = d.use_primitive_id ? primitive : 0u;
          fb.normal[o] = N;
          if (options.mode != RenderMode::Visibility)
            fb.color[o] = shade_local(*d.material, P, N, V, scene.ambient, samples);
        }
      }
      if (progress) progress->advance(uint64_t(r.size()) * uint64_t(w));
    });
  });
  out.stats["time.shade"] = seconds_since(t);

  TileCounters sum;
  for (const TileCounters& c : counters) {
    sum.generated += c.generated;
    sum.blocks_rejected += c.blocks_rejected;
    sum.triangles_rejected += c.triangles_rejected;
    sum.blocks_full += c.blocks_full;
  }
  uint64_t covered = 0;
  for (size_t i = 0; i < fb.pixel_count(); ++i) covered += target.covered(i) ? 1 : 0;
  out.stats["triangles.submitted"] = double(submitted);
  out.stats["triangles.clipped"] = double(clipped);
  out.stats["triangles.setup"] = double(set_up);
  out.stats["fragments.generated"] = double(sum.generated);
  out.stats["fragments.shaded"] = double(covered);
  out.stats["pixels.covered"] = double(covered);
  out.stats["overdraw"] = covered > 0 ? double(sum.generated) / double(covered) : 0.0;
  out.stats["blocks.full"] = double(sum.blocks_full);
  out.stats["hiz.blocks_rejected"] = double(sum.blocks_rejected);
  out.stats["hiz.triangles_rejected"] = double(sum.triangles_rejected);
  out.stats["memory.raster_bytes"] = double(target.bytes() + peak_chunk_bytes);
  out.info["hiz"] = options.hiz ? "on" : "off";

  if (!skipped_csg.empty()) {
    std::string names;
    for (const std::string& s : skipped_csg) names += (names.empty() ? "" : ", ") + s;
    out.warnings.push_back(fmt::format("csg objects have no z-buffer form: skipped {} ({})",
                                       skipped_csg.size(), names));
  }
  if (options.mode == RenderMode::Full) {
    if (!scene.lights.empty())
      out.warnings.push_back("shadows not rendered by softraster (no shadow maps yet)");
    if (mirror) out.warnings.push_back("mirror reflection not rendered by softraster");
    if (transparency) out.warnings.push_back("transparency not rendered by softraster");
    if (scene.camera.aperture_radius > 0.0f)
      out.warnings.push_back("depth of field (aperture) not rendered by softraster: pinhole");
  }
  if (scene.image.samples_per_pixel > 1)
    out.warnings.push_back(
        fmt::format("softraster: {} samples per pixel requested; multisampling is not "
                    "implemented, rendered 1",
                    scene.image.samples_per_pixel));
  return out;
}

}  // namespace

Expected<RenderOutput> SoftRasterizer::render(const Scene& scene, const RenderOptions& options) {
  try {
    return render_impl(scene, options);
  } catch (const std::bad_alloc&) {
    return internal_error(fmt::format("out of memory rendering {}x{} with {} objects",
                                      scene.image.width, scene.image.height, scene.objects.size()));
  }
}

}  // namespace rvr
