#include "soft/draw_triangles.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <utility>

#include "rvr/core/check.h"
#include "rvr/core/timer.h"
#include "soft/fill_kernel.h"
#include "soft/huge_page_allocator.h"
#include "soft/setup_kernel.h"
#include "soft/setup_triangle.h"
#include "soft/triangle_setup.h"

namespace rvr::soft {
namespace {

using Clock = std::chrono::steady_clock;

// Triangles stream through in chunks of kChunk (in submission order), each set up by kSubChunk at
// a time in parallel, binned, and drawn into every tile before the next: memory holds one chunk,
// whatever the triangle count. Each chunk's tile pass fetches again the frame-buffer lines its
// triangles touch: scattered triangles (a soup) touch most of the frame in every chunk, so fewer,
// larger chunks save that traffic; 262,144 set-up triangles are 32 MiB, well inside the memory
// target at 10^7.
constexpr size_t kChunk = size_t(1) << 18;
// 8192 set-up triangles are 1 MiB, in one huge page each (HugePageAllocator).
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

// The tiles a set-up triangle's pixel box overlaps, kept per sub-chunk for the binning's second
// pass: 8 bytes a triangle to read instead of its 64-byte first line.
struct TileSpan {
  uint16_t x0, y0, x1, y1;
};
static_assert(kMaxImageSide / kTile <= 65536, "tile indices fit 16 bits");

// What every sub-chunk's setup shares: the kernels, the projection and the viewport.
struct SetupContext {
  const FillKernels& kernels;
  ProjectionParams params;
  int width, height;
  std::optional<glm::dvec4> keep;  // a user clip plane in the world (TriangleSetup's)
};

// The triangle (a, b, c of the batch's vertices) clipped or batched: trivially outside the view
// frustum (`reject`): counted as clipped; crossing the near or a guard plane (`clip`): through
// the scalar clipper, in order; otherwise it joins the batch as slot batch.count.
void set_up_one(const SetupContext& ctx, SetupWorker& worker, const TriangleMesh& m,
                const glm::uvec3& tri, uint32_t object, uint32_t primitive, bool reject, bool clip,
                SetupTriangles& local, size_t& local_clipped) {
  if (reject) {
    ++local_clipped;
    return;
  }
  if (clip) {
    worker.flush(ctx.kernels, ctx.width, ctx.height, local);
    worker.setup.add(
        worker.setup.project(m.positions[tri.x]), worker.setup.project(m.positions[tri.y]),
        worker.setup.project(m.positions[tri.z]), object, primitive, local, local_clipped);
    return;
  }
  SetupBatch& batch = worker.batch;
  const int k = batch.count;
  batch.object[k] = object;
  batch.primitive[k] = primitive;
  if (++batch.count == kSetupBatch) worker.flush(ctx.kernels, ctx.width, ctx.height, local);
}

// Triangles tris[0 .. n) of mesh m (primitives from `primitive0`), whose vertices lie in
// [lo, lo + span): the range projected at once, then each triangle culled, clipped (scalar
// path) or batched by vertex index, in order.
void set_up_range(const SetupContext& ctx, SetupWorker& worker, const TriangleMesh& m,
                  uint32_t object, const glm::uvec3* tris, size_t n, uint32_t primitive0,
                  uint32_t lo, uint32_t span, SetupTriangles& local, size_t& local_clipped) {
  worker.project_range(ctx.kernels, ctx.params, m.positions.data() + lo, span);
  if (ctx.keep)  // the kernels know the frustum only: the user plane's flags as project() sets them
    for (uint32_t v = 0; v < span; ++v)
      if (discarded_by(*ctx.keep, m.positions[lo + v])) {
        worker.range_reject[v] |= uint8_t(kUserPlaneReject);
        worker.range_clip[v] |= uint8_t(kUserPlaneClip);
      }
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
    set_up_one(ctx, worker, m, tris[i], object, primitive0 + uint32_t(i),
               (reject[a] & reject[b] & reject[c]) != 0, (clip[a] | clip[b] | clip[c]) != 0, local,
               local_clipped);
  }
  worker.flush(ctx.kernels, ctx.width, ctx.height, local);
}

// Submitted triangles [begin, end), starting in object `object`, through the worker's vertex
// cache (scattered indices, or several objects): each triangle's projected vertices copied into
// the batch's own store (a later lookup may evict them), then culled, clipped or batched.
void set_up_cached(const SetupContext& ctx, SetupWorker& worker, const DrawList& list,
                   size_t object, size_t begin, size_t end, SetupTriangles& local,
                   size_t& local_clipped) {
  SetupBatch& batch = worker.batch;
  batch.vertices = worker.batch_vertices.arrays();
  VertexStore& store = worker.batch_vertices;
  for (size_t g = begin; g < end; ++g) {
    while (g >= list.first[object + 1]) ++object;
    const TriangleMesh& m = *list.objects[object].mesh;
    const uint32_t primitive = uint32_t(g - list.first[object]);
    const glm::uvec3& tri = m.triangles[primitive];
    const uint32_t o = uint32_t(object);
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
    set_up_one(ctx, worker, m, tri, o, primitive, reject != 0, clip != 0, local, local_clipped);
  }
  worker.flush(ctx.kernels, ctx.width, ctx.height, local);
}

// Submitted triangles [begin, end) set up in order into `local`: one object's compact index
// range projected in one kernel pass, anything else through the vertex cache. Returns how many
// were clipped away.
size_t set_up_sub_chunk(const SetupContext& ctx, SetupWorker& worker, const DrawList& list,
                        size_t begin, size_t end, SetupTriangles& local) {
  local.clear();
  size_t local_clipped = 0;
  RVR_DCHECK(begin < end && end - begin <= kSubChunk, "sub-chunk [", begin, ", ", end, ")");
  local.reserve(end - begin);
  const size_t object =
      size_t(std::upper_bound(list.first.begin(), list.first.end(), begin) - list.first.begin()) -
      1;
  if (end <= list.first[object + 1]) {
    const TriangleMesh& mesh = *list.objects[object].mesh;
    const glm::uvec3* tris = mesh.triangles.data() + (begin - list.first[object]);
    const size_t n = end - begin;
    uint32_t lo = ~0u, hi = 0;
    for (size_t i = 0; i < n; ++i)
      for (int v = 0; v < 3; ++v) {
        lo = std::min(lo, tris[i][v]);
        hi = std::max(hi, tris[i][v]);
      }
    if (size_t(hi - lo) < kRangePerTriangle * n) {
      set_up_range(ctx, worker, mesh, uint32_t(object), tris, n,
                   uint32_t(begin - list.first[object]), lo, hi - lo + 1, local, local_clipped);
      return local_clipped;
    }
  }
  set_up_cached(ctx, worker, list, object, begin, end, local, local_clipped);
  return local_clipped;
}

// The chunked draw's state across chunks: per sub-chunk its set-up triangles, clipped count and
// tile spans; per tile and sub-chunk the bin counts (then offsets); the bins; per tile its
// counters.
class ChunkedDraw {
 public:
  ChunkedDraw(const DrawList& list, const glm::dmat4& view_projection,
              const std::optional<glm::dvec4>& keep, DepthTarget& target, tbb::task_arena& arena)
      : list_(list),
        target_(target),
        arena_(arena),
        ctx_{target.kernels(), projection_params(target.width(), target.height(), view_projection),
             target.width(), target.height(), keep},
        tiles_x_(target.tiles_x()),
        tile_count_(size_t(target.tiles_x()) * size_t(target.tiles_y())),
        workers_(TriangleSetup(target.width(), target.height(), view_projection, keep)),
        sub_out_((kChunk + kSubChunk - 1) / kSubChunk),
        sub_clipped_(sub_out_.size()),
        sub_spans_(sub_out_.size()),
        bin_start_(tile_count_ + 1),
        counters_(tile_count_) {}

  // Sets up submitted triangles [chunk, chunk_end) in `subs` sub-chunks in parallel, each kept in
  // order, and counts their tiles while they are still in that core's cache (a pass of its own
  // read them all back from memory).
  void set_up(size_t chunk, size_t chunk_end, size_t subs, DrawResult& result) {
    counts_.assign(subs * tile_count_, 0);
    arena_.execute([&] {
      tbb::parallel_for(size_t(0), subs, [&](size_t s) {
        const size_t begin = chunk + s * kSubChunk, end = std::min(chunk_end, begin + kSubChunk);
        sub_clipped_[s] = set_up_sub_chunk(ctx_, workers_.local(), list_, begin, end, sub_out_[s]);
        count_tiles(s);
      });
    });
    for (size_t s = 0; s < subs; ++s) {
      RVR_CHECK(sub_out_[s].size() < (size_t(1) << DepthTarget::kLocalBits),
                "a sub-chunk's set-up triangles (clipping makes up to six of one) must fit a bin "
                "entry's local index: ",
                sub_out_[s].size());
      result.clipped += sub_clipped_[s];
      result.set_up += sub_out_[s].size();
    }
  }

  // A counting sort of the chunk's triangles into tiles, in submission order (the counts were
  // taken in the setup pass): offsets tile by tile, and within a tile sub-chunk by sub-chunk,
  // then every triangle's entry in each tile it overlaps.
  void bin(size_t subs) {
    uint32_t running = 0;
    for (size_t b = 0; b < tile_count_; ++b) {
      bin_start_[b] = running;
      for (size_t s = 0; s < subs; ++s) {
        uint32_t n = counts_[s * tile_count_ + b];
        counts_[s * tile_count_ + b] = running;
        running += n;
      }
    }
    bin_start_[tile_count_] = running;
    RVR_CHECK(subs <= (size_t(1) << (32 - DepthTarget::kLocalBits)),
              "a chunk's sub-chunk numbers must fit a bin entry's top bits: ", subs);
    bin_.resize(running);
    arena_.execute([&] {
      tbb::parallel_for(size_t(0), subs, [&](size_t s) {
        uint32_t* next = &counts_[s * tile_count_];
        const uint32_t tag = uint32_t(s) << DepthTarget::kLocalBits;
        const std::vector<TileSpan>& spans = sub_spans_[s];
        for (size_t i = 0; i < spans.size(); ++i)
          for_tiles(spans[i], [&](size_t b) { bin_[next[b]++] = tag | uint32_t(i); });
      });
    });
  }

  // The bytes the chunk holds: bins, counts, spans and set-up triangles.
  size_t chunk_bytes() const {
    size_t bytes = (bin_.capacity() + counts_.capacity()) * sizeof(uint32_t);
    for (const auto& spans : sub_spans_) bytes += spans.capacity() * sizeof(TileSpan);
    for (const auto& v : sub_out_)
      if (v.capacity() > 0) bytes += HugePageAllocator<SetupTriangle>::bytes_for(v.capacity());
    return bytes;
  }

  // Draws the binned triangles, tiles in parallel, each independent of the others. Returns the
  // fragments generated.
  uint64_t raster() {
    std::atomic<uint64_t> fragments{0};
    arena_.execute([&] {
      tbb::parallel_for(size_t(0), tile_count_, [&](size_t b) {
        if (bin_start_[b + 1] == bin_start_[b]) return;
        const uint64_t before = counters_[b].generated;
        target_.draw_tile(int(b % size_t(tiles_x_)), int(b / size_t(tiles_x_)), sub_out_.data(),
                          bin_.data() + bin_start_[b], bin_start_[b + 1] - bin_start_[b],
                          counters_[b]);
        fragments.fetch_add(counters_[b].generated - before, std::memory_order_relaxed);
      });
    });
    return fragments.load();
  }

  // Every tile's counters summed.
  TileCounters counters() const {
    TileCounters sum;
    for (const TileCounters& c : counters_) {
      sum.generated += c.generated;
      sum.blocks_rejected += c.blocks_rejected;
      sum.triangles_rejected += c.triangles_rejected;
      sum.blocks_full += c.blocks_full;
    }
    return sum;
  }

 private:
  template <class Fn>
  void for_tiles(const TileSpan& span, Fn&& fn) const {
    for (int ty = span.y0; ty <= span.y1; ++ty)
      for (int tx = span.x0; tx <= span.x1; ++tx) fn(size_t(ty) * size_t(tiles_x_) + size_t(tx));
  }

  // Sub-chunk s's tile spans and its counts per tile.
  void count_tiles(size_t s) {
    uint32_t* c = &counts_[s * tile_count_];
    std::vector<TileSpan>& spans = sub_spans_[s];
    spans.resize(sub_out_[s].size());
    for (size_t i = 0; i < spans.size(); ++i) {
      const SetupTriangle& st = sub_out_[s][i];
      RVR_DCHECK(st.x0 <= st.x1 && st.y0 <= st.y1 && st.x1 < ctx_.width && st.y1 < ctx_.height,
                 "setup keeps only triangles with an on-screen pixel box");
      spans[i] = {uint16_t(st.x0 / kTile), uint16_t(st.y0 / kTile), uint16_t(st.x1 / kTile),
                  uint16_t(st.y1 / kTile)};
      for_tiles(spans[i], [&](size_t b) { ++c[b]; });
    }
  }

  const DrawList& list_;
  DepthTarget& target_;
  tbb::task_arena& arena_;
  const SetupContext ctx_;
  const int tiles_x_;
  const size_t tile_count_;
  tbb::enumerable_thread_specific<SetupWorker> workers_;
  std::vector<SetupTriangles> sub_out_;
  std::vector<size_t> sub_clipped_;
  std::vector<std::vector<TileSpan>> sub_spans_;
  std::vector<uint32_t> counts_, bin_start_, bin_;
  std::vector<TileCounters> counters_;
};

}  // namespace

DrawList make_draw_list(std::vector<DrawObject> objects) {
  DrawList list;
  list.objects = std::move(objects);
  list.first.assign(list.objects.size() + 1, 0);
  for (size_t i = 0; i < list.objects.size(); ++i) {
    const DrawObject& d = list.objects[i];
    list.first[i + 1] = list.first[i] + (d.mesh && !d.csg ? d.mesh->triangles.size() : 0);
  }
  return list;
}

DrawResult draw_triangles(const DrawList& list, const glm::dmat4& view_projection,
                          DepthTarget& target, tbb::task_arena& arena, ProgressSink* progress,
                          const std::optional<glm::dvec4>& keep) {
  DrawResult result;
  ChunkedDraw draw(list, view_projection, keep, target, arena);
  const size_t submitted = list.triangles();
  for (size_t chunk = 0; chunk < submitted; chunk += kChunk) {
    if (is_cancelled(progress)) break;  // the caller returns cancelled_error()
    const size_t chunk_end = std::min(submitted, chunk + kChunk);
    const size_t subs = (chunk_end - chunk + kSubChunk - 1) / kSubChunk;
    auto t = Clock::now();
    draw.set_up(chunk, chunk_end, subs, result);  // transform, cull, clip; count tiles
    result.setup_seconds += seconds_since(t);
    t = Clock::now();
    draw.bin(subs);
    result.bin_seconds += seconds_since(t);
    result.peak_chunk_bytes = std::max(result.peak_chunk_bytes, draw.chunk_bytes());
    t = Clock::now();
    const uint64_t fragments = draw.raster();
    result.raster_seconds += seconds_since(t);
    if (progress) progress->advance(chunk_end - chunk, fragments);
  }
  result.counters = draw.counters();
  return result;
}

}  // namespace rvr::soft
