#include "zbuffer_hits.h"

#include <emmintrin.h>
#include <stddef.h>
#include <xmmintrin.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <utility>
#include <vector>

#include "rvr/core/check.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/prefetch.h"
#include "rvr/raytrace/packet_slots.h"
#include "rvr/raytrace/primary_rays.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {
namespace {

// A block with at least this many pixels to trace traces them as one packet.
constexpr int kPacketFallbacks = 8;

// Whether `other` is nearer than `hit` by closest()'s rule (a tie goes to the lower primitive
// index); if so `hit` becomes it.
bool take_if_nearer(const HitRecord& other, HitRecord& hit) {
  if (!(other.t < hit.t || (other.t == hit.t && other.primitive < hit.primitive))) return false;
  hit = other;
  return true;
}

// The first w of `row` into `to`: a whole block's row (the usual case) by a copy of constant
// size, which the compiler inlines.
template <class T>
void copy_row(const T* row, int w, T* to) {
  if (w == kPacketSide)
    std::memcpy(to, row, kPacketSide * sizeof(T));
  else
    std::copy_n(row, w, to);
}

// Bit x set where row[x] != kNoId (drawn), for the first w of `row`: a whole block's row as two
// SSE2 compares (baseline x86-64).
uint64_t drawn_bits(const uint32_t* row, int w) {
  static_assert(kPacketSide == 8 && kNoId == 0xFFFFFFFFu);
  if (w == kPacketSide) {
    const __m128i none = _mm_set1_epi32(-1);
    const __m128i lo =
        _mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row)), none);
    const __m128i hi =
        _mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 4)), none);
    const int empty = _mm_movemask_ps(_mm_castsi128_ps(lo)) | _mm_movemask_ps(_mm_castsi128_ps(hi))
                                                                  << 4;
    return uint64_t(~empty & 0xFF);
  }
  uint64_t bits = 0;
  for (int x = 0; x < w; ++x) bits |= uint64_t(row[x] != kNoId) << x;
  return bits;
}

// Bit x set where row[x] != 0, for the first w of `row`: a whole block's row as one SSE2 compare.
uint64_t set_bits(const uint8_t* row, int w) {
  if (w == kPacketSide) {
    const __m128i zero =
        _mm_cmpeq_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(row)), _mm_setzero_si128());
    return uint64_t(~_mm_movemask_epi8(zero) & 0xFF);
  }
  uint64_t bits = 0;
  for (int x = 0; x < w; ++x) bits |= uint64_t(row[x] != 0) << x;
  return bits;
}

// Whether any of the n bytes at p is non-zero: eight at a time.
bool any_set(const uint8_t* p, int n) {
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    uint64_t word;
    std::memcpy(&word, p + i, sizeof(word));
    if (word != 0) return true;
  }
  for (; i < n; ++i)
    if (p[i] != 0) return true;
  return false;
}

}  // namespace

ZBufferHits::ZBufferHits(const Scene& scene, const TraceGeometry& geometry,
                         const PrimaryVisibility& visible, std::span<const uint8_t> approximated)
    : scene_(scene), geometry_(geometry), visible_(visible), approximated_(approximated) {}

HybridCounters ZBufferHits::counters() const {
  HybridCounters total;
  counters_.combine_each([&](const HybridCounters& c) { total.add(c); });
  return total;
}

// No pixel of the block can show anything to the tracer: the z-buffer covered none of them nor
// of their neighbours, and none lies where a shape it draws approximately or not at all may
// appear (centre_hits' tests for the whole block at once).
bool ZBufferHits::only_background(int x0, int y0, int x1, int y1) const {
  const size_t width = size_t(visible_.width);
  if (!approximated_.empty())
    for (int y = y0; y < y1; ++y)
      if (any_set(approximated_.data() + size_t(y) * width + size_t(x0), x1 - x0)) return false;
  const int nx0 = std::max(x0 - 1, 0), nx1 = std::min(x1 + 1, visible_.width);
  for (int y = std::max(y0 - 1, 0); y < std::min(y1 + 1, visible_.height); ++y) {
    const uint32_t* row = visible_.object_id.data() + size_t(y) * width;
    uint32_t all = ~0u;  // kNoId where every id is kNoId
    for (int x = nx0; x < nx1; ++x) all &= row[x];
    if (all != kNoId) return false;
  }
  counters_.local().background += uint64_t(x1 - x0) * uint64_t(y1 - y0);
  return true;
}

// Whether empty pixel (x, y) lies next to a pixel the z-buffer covered: a silhouette or shared
// edge may fall either way at its centre, so the tracer may see any surface there.
bool ZBufferHits::next_to_drawn(int x, int y) const {
  const size_t width = size_t(visible_.width);
  for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, visible_.height - 1); ++ny)
    for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, visible_.width - 1); ++nx)
      if (visible_.object_id[size_t(ny) * width + size_t(nx)] != kNoId) return true;
  return false;
}

bool ZBufferHits::approximated_wins(const Ray& ray, HitRecord& hit, TraversalCounters& work) const {
  HitRecord shape;
  return geometry_.closest_approximated(ray, shape, work) && take_if_nearer(shape, hit);
}

bool ZBufferHits::csg_hit(const HitRecord& hit) const {
  return hit.primitive != kNoPrimitive &&
         scene_.objects[geometry_.hit_ids(hit).first].type == ObjectType::Csg;
}

// The ids of the block to the right of `block` (the next a tile's thread asks for, as wide): asked
// of the cache ahead, since a visibility buffer is larger than a core's L2 cache and its rows lie a
// frame's width apart, which the hardware prefetchers do not follow from one row to the next.
void ZBufferHits::fetch_next_block(const CentreBlock& block) const {
  const int x0 = block.x1, x1 = std::min(block.x1 + (block.x1 - block.x0), visible_.width);
  if (x0 >= x1) return;
  for (int y = block.y0; y < block.y1; ++y) {
    const size_t i0 = size_t(y) * size_t(visible_.width) + size_t(x0);
    const size_t i1 = i0 + size_t(x1 - x0 - 1);
    for (const uint32_t* ids : {visible_.object_id.data(), visible_.primitive_id.data()}) {
      prefetch(ids + i0);
      prefetch(ids + i1);
    }
  }
}

// For each row of the block, bit x - x0 set where pixel (x, y) or one of its eight neighbours
// was drawn: next_to_drawn for a whole row at once, each id of the block's border read once.
void ZBufferHits::drawn_nearby(const CentreBlock& block, uint32_t* rows) const {
  RVR_DCHECK(block.x1 - block.x0 <= kPacketSide && block.y1 - block.y0 <= kPacketSide,
             "a block of at most kPacketSide pixels on a side");
  const int nx0 = std::max(block.x0 - 1, 0), nx1 = std::min(block.x1 + 1, visible_.width);
  auto drawn_row = [&](int y) {  // bit x - x0 + 1 set where (x, y) was drawn, x in [x0 - 1, x1]
    uint32_t m = 0;
    if (y < 0 || y >= visible_.height) return m;
    const uint32_t* ids = visible_.object_id.data() + size_t(y) * size_t(visible_.width);
    for (int x = nx0; x < nx1; ++x) m |= uint32_t(ids[x] != kNoId) << (x - block.x0 + 1);
    return m;
  };
  uint32_t above = drawn_row(block.y0 - 1), here = drawn_row(block.y0);
  for (int y = block.y0; y < block.y1; ++y) {
    const uint32_t below = drawn_row(y + 1);
    const uint32_t column = above | here | below;
    // Bit x - x0 of the result: columns x - 1, x and x + 1, bits x - x0 .. x - x0 + 2.
    rows[y - block.y0] = column | column >> 1 | column >> 2;
    above = here;
    here = below;
  }
}

void ZBufferHits::centre_hits(CentreBlock& block) const {
  HybridCounters& counters = counters_.local();
  const RayPacket& packet = block.packet;
  const int n = packet.count, w = block.x1 - block.x0;
  HitRecord* hits = block.hits;
  TraversalCounters* work = block.work;
  // The ids the z-buffer drew, and as masks of the block's rays (bit k: ray k, pixel
  // (x0 + k % w, y0 + k / w)) which it drew and where a shape it draws approximately or not at
  // all may appear.
  uint32_t object[kPacketRays], primitive[kPacketRays];
  uint64_t drawn = 0, approximate = 0;
  for (int y = block.y0, k = 0; y < block.y1; ++y, k += w) {
    const size_t i = size_t(y) * size_t(visible_.width) + size_t(block.x0);
    copy_row(visible_.object_id.data() + i, w, object + k);
    copy_row(visible_.primitive_id.data() + i, w, primitive + k);
    if (!visible_.lod.empty()) copy_row(visible_.lod.data() + i, w, block.given_lod + k);
    drawn |= drawn_bits(object + k, w) << k;
    if (!approximated_.empty()) approximate |= set_bits(approximated_.data() + i, w) << k;
  }
  std::fill_n(block.given, n, false);
  std::fill_n(work, n, TraversalCounters{});
  fetch_next_block(block);
  // An empty pixel's hit starts as a miss. Empty next to a pixel the z-buffer covered, it is
  // traced: a silhouette or shared edge may fall either way at its centre, so the tracer may see
  // any surface there. (A block the z-buffer covered whole asks nothing of its neighbours.)
  const uint64_t empty = ~drawn & packet.all();
  uint64_t traced = 0;
  if (empty != 0) {
    uint32_t near_drawn[kPacketSide];
    drawn_nearby(block, near_drawn);
    const uint32_t row = (uint32_t(1) << w) - 1;
    for (int r = 0; r < block.y1 - block.y0; ++r)
      traced |= uint64_t(near_drawn[r] & row) << (r * w);
    traced &= empty;
    for (uint64_t m = empty; m != 0; m &= m - 1) hits[__builtin_ctzll(m)] = HitRecord{};
  }
  // Otherwise empty, background to the z-buffer away from every edge it drew: background to the
  // tracer too, without a ray, unless a shape the z-buffer draws approximately may appear there.
  const uint64_t away = empty & ~traced;
  const uint64_t background = away & ~approximate;
  const uint64_t rebuilt =
      geometry_.intersect_named_packet(packet, object, primitive, drawn, hits, work);
  // Where such a shape may appear, the nearest of those shapes, for the block's rays at once:
  // asked of the empty pixels away from every edge, and of the rebuilt ones.
  const uint64_t ask_shapes = approximate & (rebuilt | away);
  PacketSlots<HitRecord> shape;  // written where found
  const uint64_t shape_found =
      ask_shapes ? geometry_.closest_approximated_packet(packet, ask_shapes, shape.data(), work)
                 : 0;
  // Empty, away from every edge, where such a shape may appear: no triangle lies under the
  // centre, so the nearest of those shapes is the hit, or the background.
  const uint64_t shape_only = away & approximate;
  counters.fallback_traced += uint64_t(std::popcount(shape_only));
  counters.approximated_pixels += uint64_t(std::popcount(shape_only & shape_found));
  for (uint64_t m = shape_only & shape_found; m != 0; m &= m - 1) {
    const int k = __builtin_ctzll(m);
    hits[k] = shape[k];
  }
  // The z-buffer's polygon covers the centre where the exact surface does not (silhouettes,
  // shared edges): the tracer decides, below.
  const uint64_t missed = drawn & ~rebuilt;
  counters.fallback_missed += uint64_t(std::popcount(missed));
  traced |= missed;
  counters.rebuilt += uint64_t(std::popcount(rebuilt));
  // A hit rebuilt from the z-buffer samples its texture at the z-buffer's level.
  if (!visible_.lod.empty())
    for (uint64_t m = rebuilt; m != 0; m &= m - 1) block.given[__builtin_ctzll(m)] = true;
  // A shape the z-buffer draws approximately may lie in front of what it drew (a sphere's rim
  // outside its inscribed polygon): checked as sample_hits checks every sample.
  for (uint64_t m = rebuilt & shape_found; m != 0; m &= m - 1) {
    const int k = __builtin_ctzll(m);
    if (!take_if_nearer(shape[k], hits[k])) continue;
    block.given[k] = false;
    counters.approximated_pixels++;
  }
  const int n_traced = std::popcount(traced);
  counters.fallback_traced += uint64_t(n_traced);
  if (n_traced >= kPacketFallbacks) {
    // Many to trace (an empty background): the whole block as one packet, as the tracer traces
    // it; its hits are closest()'s, so which way is taken changes no pixel.
    PacketSlots<HitRecord> packet_hits;
    PacketSlots<TraversalCounters> packet_work;
    geometry_.closest_packet(packet, packet_hits.data(), packet_work.data());
    for (int k = 0; k < n; ++k) {
      if ((traced >> k) & 1) {
        hits[k] = packet_hits[k];
        work[k] = packet_work[k];
      } else {  // traversed for nothing, but traversed: counted, not charged to the pixel
        block.unattributed.nodes_visited += packet_work[k].nodes_visited;
        block.unattributed.primitive_tests += packet_work[k].primitive_tests;
      }
    }
  } else {
    for (uint64_t m = traced; m != 0; m &= m - 1) {
      const int k = __builtin_ctzll(m);
      hits[k] = HitRecord{};
      geometry_.closest(PrimaryRays::ray_of(packet, k), hits[k], work[k]);
    }
  }
  if (geometry_.has_csg())
    for (int k = 0; k < n; ++k) counters.csg_pixels += csg_hit(hits[k]);
  const int n_background = std::popcount(background);
  counters.background += uint64_t(n_background);
  block.rays = uint64_t(n - n_background);
}

void ZBufferHits::sample_hits(SampleBlock& block) const {
  HybridCounters& counters = counters_.local();
  for (int y = block.y0, j = 0; y < block.y1; ++y)
    for (int x = block.x0; x < block.x1; ++x, ++j) {
      const size_t i = size_t(y) * size_t(visible_.width) + size_t(x);
      const Ray& ray = block.rays[j];
      HitRecord& hit = block.hits[j];
      hit = HitRecord{};
      const bool rebuilt = visible_.object_id[i] != kNoId && !approximated_at(i) &&
                           geometry_.intersect_named(ray, visible_.object_id[i],
                                                     visible_.primitive_id[i], hit, block.work);
      // A hit rebuilt from the z-buffer samples its texture at the z-buffer's level.
      block.given[j] = rebuilt && !visible_.lod.empty();
      if (block.given[j]) block.given_lod[j] = visible_.lod[i];
      if (rebuilt) {
        counters.rebuilt++;
        // A sample's ray is jittered in its pixel and leaves from its lens point: the centre
        // rays' screen bounds of the shapes the z-buffer draws approximately do not bound where
        // it meets them. Every rebuilt hit is checked against those shapes instead (a sphere's
        // rim outside its inscribed polygon, in front of what the z-buffer drew there); the
        // nearer wins, as closest() would have it. No triangle lies nearer: the one the z-buffer
        // drew is the nearest, and an approximated shape's polygon lies inside the shape.
        if (geometry_.has_approximated() && approximated_wins(ray, hit, block.work)) {
          block.given[j] = false;
          counters.approximated_pixels++;
        }
      } else if (visible_.object_id[i] == kNoId && !next_to_drawn(x, y)) {
        // Empty away from every edge the pass drew: the pass was drawn through this sample's
        // place and lens point, so no triangle lies on its ray, as for an empty centre (see
        // centre_hits). Only the shapes the z-buffer draws approximately or not at all may.
        // (Its ray was made and is counted as primary: hybrid.background stays the centre's.)
        if (geometry_.has_approximated()) {
          counters.fallback_traced++;
          counters.approximated_pixels += geometry_.closest_approximated(ray, hit, block.work);
        }
      } else {
        counters.fallback_traced++;
        counters.fallback_missed += visible_.object_id[i] != kNoId && !approximated_at(i);
        if (!geometry_.closest(ray, hit, block.work)) hit = HitRecord{};
      }
      if (geometry_.has_csg()) counters.csg_pixels += csg_hit(hit);
    }
}

}  // namespace rvr
