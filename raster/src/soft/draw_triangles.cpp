#include "soft/draw_triangles.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "rvr/shared/check.h"
#include "rvr/shared/timer.h"
#include "soft/setup_kernel.h"
#include "soft/triangle_setup.h"

namespace rvr::soft {
namespace {

using Clock = std::chrono::steady_clock;

// Triangles stream through in chunks of kChunk (in submission order), each set up by kSubChunk at
// a time in parallel, binned, and drawn into every tile before the next: memory holds one chunk,
// whatever the triangle count. Each chunk's tile pass fetches again the frame-buffer lines its
// triangles touch: scattered triangles (a soup) touch most of the frame in every chunk, so fewer,
// larger chunks save that traffic; 262,144 set-up triangles are 48 MiB, well inside the memory
// target at 10^7.
constexpr size_t kChunk = size_t(1) << 18;
// 8192 set-up triangles are 1.5 MiB: one huge page each (HugePageAllocator).
constexpr size_t kSubChunk = 8192;

// A sub-chunk whose vertex indices span at most this many vertices per triangle is projected as
// one index range (a mesh like a tessellated sphere: about half a vertex per triangle, or a soup:
// three); wider spans (scattered indices) go through the vertex cache instead.
constexpr size_t kRangePerTriangle = 4;

// Growable SoA storage for VertexArrays.
struct VertexStore {
  std::vector<int32_t> fx, fy;
  std::vector<double> sx, sy, w, inv_w;
  void resize(size_t n) {
    if (fx.size() >= n) return;
    for (auto* v : {&fx, &fy}) v->resize(n);
    for (auto* v : {&sx, &sy, &w, &inv_w}) v->resize(n);
  }
  VertexArrays arrays() {
    return {fx.data(), fy.data(), sx.data(), sy.data(), w.data(), inv_w.data()};
  }
};

// A thread's setup state: its own clipping scratch, the projected vertices of the sub-chunk's
// index range (or a cache of projected vertices for scattered indices: a mesh's neighbouring
// triangles share them, so most are projected once, not once per triangle) and the batch of
// unclipped triangles waiting for the setup kernel.
struct SetupWorker {
  static constexpr size_t kCacheSize = 4096;
  explicit SetupWorker(const TriangleSetup& prototype)
      : setup(prototype), keys(kCacheSize, ~0ull), cache(kCacheSize) {
    batch_vertices.resize(3 * kSetupBatch);
  }
  const ProjectedVertex& vertex(uint32_t object, uint32_t index, const glm::vec3& p) {
    const uint64_t key = uint64_t(object) << 32 | index;
    const size_t slot = (index ^ object * 0x9E3779B1u) & (kCacheSize - 1);
    if (keys[slot] != key) {
      keys[slot] = key;
      cache[slot] = setup.project(p);
    }
    return cache[slot];
  }
  // Projects vertices [first, first + count) of `positions` into the range arrays.
  void project_range(const FillKernels& kernels, const ProjectionParams& params,
                     const glm::vec3* positions, size_t count) {
    range.resize(count);
    if (range_reject.size() < count) {
      range_reject.resize(count);
      range_clip.resize(count);
    }
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "packed float triples");
    kernels.project(params, &positions->x, count,
                    {range.arrays(), range_reject.data(), range_clip.data()});
  }
  // Sets up the waiting batch into `out` (after what is there: submission order).
  void flush(const FillKernels& kernels, int width, int height, SetupTriangles& out) {
    if (batch.count == 0) return;
    const size_t at = out.size();
    out.resize(at + size_t(batch.count));
    const int kept = kernels.setup(batch, width, height, out.data() + at);
    out.resize(at + size_t(kept));
    batch.count = 0;
  }
  TriangleSetup setup;
  std::vector<uint64_t> keys;
  std::vector<ProjectedVertex> cache;
  VertexStore range, batch_vertices;  // a sub-chunk's index range; the cached path's batch copy
  std::vector<uint8_t> range_reject, range_clip;
  SetupBatch batch;
};

// The batch kernel's 32-bit fixed point holds the vertex exactly (see kScalarOnly).
bool fits_32_bits(const ProjectedVertex& p) {
  constexpr int64_t kLimit = int64_t(1) << 29;
  return p.fx > -kLimit && p.fx < kLimit && p.fy > -kLimit && p.fy < kLimit;
}

ProjectionParams projection_params(int width, int height, const glm::dmat4& view_projection) {
  ProjectionParams p{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) p.m[c][r] = view_projection[c][r];
  p.width = width;
  p.height = height;
  // TriangleSetup's guard planes' w terms.
  p.gx = kGuardPixels / width;
  p.gy = kGuardPixels / height;
  return p;
}

}  // namespace

DrawList make_draw_list(std::vector<DrawObject> objects) {
  DrawList list;
  list.objects = std::move(objects);
  list.first.assign(list.objects.size() + 1, 0);
  for (size_t i = 0; i < list.objects.size(); ++i) {
    const TriangleMesh* m = list.objects[i].mesh;
    list.first[i + 1] = list.first[i] + (m ? m->triangles.size() : 0);
  }
  return list;
}

DrawResult draw_triangles(const DrawList& list, const glm::dmat4& view_projection,
                          DepthTarget& target, tbb::task_arena& arena, ProgressSink* progress) {
  DrawResult result;
  const size_t submitted = list.triangles();
  const size_t tile_count = size_t(target.tiles_x()) * size_t(target.tiles_y());
  const int tiles_x = target.tiles_x();
  const int width = target.width(), height = target.height();
  const FillKernels& kernels = target.kernels();
  const TriangleSetup prototype(target.width(), target.height(), view_projection);
  tbb::enumerable_thread_specific<SetupWorker> workers(prototype);
  std::vector<SetupTriangles> sub_out((kChunk + kSubChunk - 1) / kSubChunk);
  std::vector<size_t> sub_clipped(sub_out.size());
  std::vector<uint32_t> counts, bin_start(tile_count + 1), bin;
  std::vector<TileCounters> counters(tile_count);
  // The tiles a set-up triangle's pixel box overlaps, kept per sub-chunk for the binning's
  // second pass: 8 bytes a triangle to read instead of its 64-byte first line.
  struct TileSpan {
    uint16_t x0, y0, x1, y1;
  };
  static_assert(kMaxImageSide / kTile <= 65536, "tile indices fit 16 bits");
  std::vector<std::vector<TileSpan>> sub_spans(sub_out.size());
  auto for_tiles = [&](const TileSpan& span, auto&& fn) {
    for (int ty = span.y0; ty <= span.y1; ++ty)
      for (int tx = span.x0; tx <= span.x1; ++tx) fn(size_t(ty) * size_t(tiles_x) + size_t(tx));
  };
  const ProjectionParams params = projection_params(width, height, view_projection);
  // Triangles tris[0 .. n) of mesh m (primitives from `primitive0`), whose vertices lie in
  // [lo, lo + span): the range projected at once, then each triangle culled, clipped (scalar
  // path) or batched by vertex index, in order.
  auto set_up_range = [&](SetupWorker& worker, const TriangleMesh& m, uint32_t object,
                          const glm::uvec3* tris, size_t n, uint32_t primitive0, uint32_t lo,
                          uint32_t span, SetupTriangles& local, size_t& local_clipped) {
    worker.project_range(kernels, params, m.positions.data() + lo, span);
    SetupBatch& batch = worker.batch;
    batch.vertices = worker.range.arrays();
    const uint8_t* reject = worker.range_reject.data();
    const uint8_t* clip = worker.range_clip.data();
    for (size_t i = 0; i < n; ++i) {
      const uint32_t a = tris[i].x - lo, b = tris[i].y - lo, c = tris[i].z - lo;
      const int k = batch.count;
      batch.vertex[0][k] = a;
      batch.vertex[1][k] = b;
      batch.vertex[2][k] = c;
      if (reject[a] & reject[b] & reject[c]) {  // trivially outside the view frustum
        ++local_clipped;
        continue;
      }
      const uint32_t primitive = primitive0 + uint32_t(i);
      if (clip[a] | clip[b] | clip[c]) {  // the scalar clipper, in order
        worker.flush(kernels, width, height, local);
        worker.setup.add(worker.setup.project(m.positions[tris[i].x]),
                         worker.setup.project(m.positions[tris[i].y]),
                         worker.setup.project(m.positions[tris[i].z]), object, primitive, local,
                         local_clipped);
        continue;
      }
      batch.object[k] = object;
      batch.primitive[k] = primitive;
      if (++batch.count == kSetupBatch) worker.flush(kernels, width, height, local);
    }
    worker.flush(kernels, width, height, local);
  };
  for (size_t chunk = 0; chunk < submitted; chunk += kChunk) {
    if (is_cancelled(progress)) break;  // the caller returns cancelled_error()
    const size_t chunk_end = std::min(submitted, chunk + kChunk);
    const size_t subs = (chunk_end - chunk + kSubChunk - 1) / kSubChunk;
    // --- setup: transform, cull, clip; sub-chunks in parallel, kept in order
    auto t = Clock::now();
    counts.assign(subs * tile_count, 0);
    arena.execute([&] {
      auto set_up_sub_chunk = [&](size_t s) {
        SetupWorker& worker = workers.local();
        SetupTriangles& local = sub_out[s];
        local.clear();
        size_t local_clipped = 0;
        const size_t begin = chunk + s * kSubChunk, end = std::min(chunk_end, begin + kSubChunk);
        RVR_DCHECK(begin < end && end - begin <= kSubChunk, "sub-chunk [", begin, ", ", end, ")");
        local.reserve(end - begin);
        size_t object = size_t(std::upper_bound(list.first.begin(), list.first.end(), begin) -
                               list.first.begin()) -
                        1;
        SetupBatch& batch = worker.batch;
        // One object and a compact index range: project the range in one kernel pass.
        const TriangleMesh& first_mesh = *list.objects[object].mesh;
        if (end <= list.first[object + 1]) {
          const glm::uvec3* tris = first_mesh.triangles.data() + (begin - list.first[object]);
          const size_t n = end - begin;
          uint32_t lo = ~0u, hi = 0;
          for (size_t i = 0; i < n; ++i)
            for (int v = 0; v < 3; ++v) {
              lo = std::min(lo, tris[i][v]);
              hi = std::max(hi, tris[i][v]);
            }
          if (size_t(hi - lo) < kRangePerTriangle * n) {
            set_up_range(worker, first_mesh, uint32_t(object), tris, n,
                         uint32_t(begin - list.first[object]), lo, hi - lo + 1, local,
                         local_clipped);
            sub_clipped[s] = local_clipped;
            return;
          }
        }
        batch.vertices = worker.batch_vertices.arrays();
        VertexStore& store = worker.batch_vertices;
        for (size_t g = begin; g < end; ++g) {
          while (g >= list.first[object + 1]) ++object;
          const TriangleMesh& m = *list.objects[object].mesh;
          const uint32_t primitive = uint32_t(g - list.first[object]);
          const glm::uvec3& tri = m.triangles[primitive];
          const uint32_t o = uint32_t(object);
          // The vertices straight into the batch's own copy (a later lookup may evict them).
          const int k = batch.count;
          uint32_t reject = ~0u, clip = 0;
          for (int v = 0; v < 3; ++v) {
            const ProjectedVertex& p = worker.vertex(o, tri[v], m.positions[tri[v]]);
            reject &= p.reject;
            clip |= p.clip_planes;
            const uint32_t at = uint32_t(v * kSetupBatch + k);
            clip |= fits_32_bits(p) ? 0u : kScalarOnly;
            store.fx[at] = int32_t(p.fx);
            store.fy[at] = int32_t(p.fy);
            store.sx[at] = p.sx;
            store.sy[at] = p.sy;
            store.w[at] = p.clip.w;
            store.inv_w[at] = p.inv_w;
            batch.vertex[v][k] = at;
          }
          if (reject) {  // trivially outside the view frustum
            ++local_clipped;
            continue;
          }
          if (clip) {  // crosses the near or a guard plane: the scalar clipper, in order
            worker.flush(kernels, width, height, local);
            worker.setup.add(
                worker.setup.project(m.positions[tri.x]), worker.setup.project(m.positions[tri.y]),
                worker.setup.project(m.positions[tri.z]), o, primitive, local, local_clipped);
            continue;
          }
          batch.object[k] = o;
          batch.primitive[k] = primitive;
          if (++batch.count == kSetupBatch) worker.flush(kernels, width, height, local);
        }
        worker.flush(kernels, width, height, local);
        sub_clipped[s] = local_clipped;
      };
      tbb::parallel_for(size_t(0), subs, [&](size_t s) {
        set_up_sub_chunk(s);
        // The binning's counts, while the sub-chunk's triangles are still in this core's cache
        // (a pass of its own read them all back from memory).
        uint32_t* c = &counts[s * tile_count];
        std::vector<TileSpan>& spans = sub_spans[s];
        spans.resize(sub_out[s].size());
        for (size_t i = 0; i < spans.size(); ++i) {
          const SetupTriangle& st = sub_out[s][i];
          RVR_DCHECK(st.x0 <= st.x1 && st.y0 <= st.y1 && st.x1 < width && st.y1 < height,
                     "setup keeps only triangles with an on-screen pixel box");
          spans[i] = {uint16_t(st.x0 / kTile), uint16_t(st.y0 / kTile), uint16_t(st.x1 / kTile),
                      uint16_t(st.y1 / kTile)};
          for_tiles(spans[i], [&](size_t b) { ++c[b]; });
        }
      });
    });
    for (size_t s = 0; s < subs; ++s) {
      RVR_CHECK(sub_out[s].size() < (size_t(1) << DepthTarget::kLocalBits),
                "a sub-chunk's set-up triangles (clipping makes up to six of one) must fit a bin "
                "entry's local index: ",
                sub_out[s].size());
      result.clipped += sub_clipped[s];
      result.set_up += sub_out[s].size();
    }
    result.setup_seconds += seconds_since(t);

    // --- bin: a counting sort of the chunk's triangles into tiles, in submission order (the
    // counts were taken in the setup pass)
    t = Clock::now();
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
    RVR_CHECK(subs <= (size_t(1) << (32 - DepthTarget::kLocalBits)),
              "a chunk's sub-chunk numbers must fit a bin entry's top bits: ", subs);
    bin.resize(running);
    arena.execute([&] {
      tbb::parallel_for(size_t(0), subs, [&](size_t s) {
        uint32_t* next = &counts[s * tile_count];
        const uint32_t tag = uint32_t(s) << DepthTarget::kLocalBits;
        const std::vector<TileSpan>& spans = sub_spans[s];
        for (size_t i = 0; i < spans.size(); ++i)
          for_tiles(spans[i], [&](size_t b) { bin[next[b]++] = tag | uint32_t(i); });
      });
    });
    result.bin_seconds += seconds_since(t);
    size_t chunk_bytes = (bin.capacity() + counts.capacity()) * sizeof(uint32_t);
    for (const auto& spans : sub_spans) chunk_bytes += spans.capacity() * sizeof(TileSpan);
    for (const auto& v : sub_out)
      if (v.capacity() > 0)
        chunk_bytes += HugePageAllocator<SetupTriangle>::bytes_for(v.capacity());
    result.peak_chunk_bytes = std::max(result.peak_chunk_bytes, chunk_bytes);

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
    result.raster_seconds += seconds_since(t);
    if (progress) progress->advance(chunk_end - chunk, fragments.load());
  }
  for (const TileCounters& c : counters) {
    result.counters.generated += c.generated;
    result.counters.blocks_rejected += c.blocks_rejected;
    result.counters.triangles_rejected += c.triangles_rejected;
    result.counters.blocks_full += c.blocks_full;
  }
  return result;
}

}  // namespace rvr::soft
