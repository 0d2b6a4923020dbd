#include "soft/draw_triangles.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "rvr/shared/timer.h"
#include "soft/setup_kernel.h"
#include "soft/triangle_setup.h"

namespace rvr::soft {
namespace {

using Clock = std::chrono::steady_clock;

// Triangles stream through in chunks of kChunk (in submission order), each set up by kSubChunk at
// a time in parallel, binned, and drawn into every tile before the next: memory holds one chunk,
// whatever the triangle count.
constexpr size_t kChunk = size_t(1) << 16;
// 8192 set-up triangles are 1.5 MiB: one huge page each (HugePageAllocator).
constexpr size_t kSubChunk = 8192;

// A thread's setup state: its own clipping scratch, a cache of projected vertices (a mesh's
// neighbouring triangles share them, so most are projected once, not once per triangle) and
// the batch of unclipped triangles waiting for the setup kernel.
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
  SetupBatch batch;
};

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
  auto for_tiles = [&](const SetupTriangle& st, auto&& fn) {
    for (int ty = st.y0 / kTile; ty <= st.y1 / kTile; ++ty)
      for (int tx = st.x0 / kTile; tx <= st.x1 / kTile; ++tx)
        fn(size_t(ty) * size_t(tiles_x) + size_t(tx));
  };
  for (size_t chunk = 0; chunk < submitted; chunk += kChunk) {
    const size_t chunk_end = std::min(submitted, chunk + kChunk);
    const size_t subs = (chunk_end - chunk + kSubChunk - 1) / kSubChunk;
    // --- setup: transform, cull, clip; sub-chunks in parallel, kept in order
    auto t = Clock::now();
    arena.execute([&] {
      tbb::parallel_for(size_t(0), subs, [&](size_t s) {
        SetupWorker& worker = workers.local();
        SetupTriangles& local = sub_out[s];
        local.clear();
        size_t local_clipped = 0;
        const size_t begin = chunk + s * kSubChunk, end = std::min(chunk_end, begin + kSubChunk);
        local.reserve(end - begin);
        size_t object = size_t(std::upper_bound(list.first.begin(), list.first.end(), begin) -
                               list.first.begin()) -
                        1;
        for (size_t g = begin; g < end; ++g) {
          while (g >= list.first[object + 1]) ++object;
          const TriangleMesh& m = *list.objects[object].mesh;
          const uint32_t primitive = uint32_t(g - list.first[object]);
          const glm::uvec3& tri = m.triangles[primitive];
          const uint32_t o = uint32_t(object);
          // The vertices straight into the batch's next slot (a later lookup may evict them).
          SetupBatch& batch = worker.batch;
          const int k = batch.count;
          uint32_t reject = ~0u, clip = 0;
          for (int v = 0; v < 3; ++v) {
            const ProjectedVertex& p = worker.vertex(o, tri[v], m.positions[tri[v]]);
            reject &= p.reject;
            clip |= p.clip_planes;
            batch.fx[v][k] = p.fx;
            batch.fy[v][k] = p.fy;
            batch.sx[v][k] = p.sx;
            batch.sy[v][k] = p.sy;
            batch.w[v][k] = p.clip.w;
            batch.inv_w[v][k] = p.inv_w;
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
      });
    });
    for (size_t s = 0; s < subs; ++s) {
      result.clipped += sub_clipped[s];
      result.set_up += sub_out[s].size();
    }
    result.setup_seconds += seconds_since(t);

    // --- bin: a counting sort of the chunk's triangles into tiles, in submission order
    t = Clock::now();
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
    result.bin_seconds += seconds_since(t);
    size_t chunk_bytes = (bin.capacity() + counts.capacity()) * sizeof(uint32_t);
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
