#include "soft/tile_raster.h"

#include <emmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <limits>

#include "rvr/core/check.h"
#include "soft/triangle_setup.h"

namespace rvr::soft {

DepthTarget::DepthTarget(int width, int height, double near_plane, double far_plane, bool hiz,
                         const FillKernels& kernels, TargetArrays arrays)
    : width_(width),
      height_(height),
      tiles_x_((width + kTile - 1) / kTile),
      tiles_y_((height + kTile - 1) / kTile),
      blocks_x_((width + kBlock - 1) / kBlock),
      blocks_y_((height + kBlock - 1) / kBlock),
      near_(near_plane),
      far_(far_plane),
      hiz_(hiz),
      arrays_{arrays.ids, arrays.ids && arrays.barycentrics, arrays.ids && arrays.fragments},
      kernels_(&kernels) {
  RVR_CHECK(width > 0 && height > 0 && width <= kMaxImageSide && height <= kMaxImageSide,
            "the renderer refuses frames outside 1..kMaxImageSide: ", width, "x", height);
  RVR_CHECK(near_plane > 0.0 && far_plane > near_plane,
            "the camera keeps 0 < near < far: ", near_plane, ", ", far_plane);
  clear();
}

void DepthTarget::resize(int width, int height) {
  RVR_CHECK(width > 0 && height > 0 && width <= kMaxImageSide && height <= kMaxImageSide,
            "the renderer refuses frames outside 1..kMaxImageSide: ", width, "x", height);
  width_ = width;
  height_ = height;
  tiles_x_ = (width + kTile - 1) / kTile;
  tiles_y_ = (height + kTile - 1) / kTile;
  blocks_x_ = (width + kBlock - 1) / kBlock;
  blocks_y_ = (height + kBlock - 1) / kBlock;
  clear();
}

void DepthTarget::clear() {
  const size_t n = size_t(width_) * size_t(height_);
  // Sized without a serial fill (tens of MB at 1024x768: a serial fill would be a serial share
  // of every frame), then filled in parallel slices.
  depth_.resize(n);
  if (arrays_.ids) {
    object_.resize(n);
    primitive_.resize(n);
  }
  if (arrays_.fragments) fragments_.resize(n);
  if (arrays_.barycentrics) bary_.resize(3 * n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14),
                    [&](const tbb::blocked_range<size_t>& r) {
                      std::fill(depth_.begin() + std::ptrdiff_t(r.begin()),
                                depth_.begin() + std::ptrdiff_t(r.end()),
                                std::numeric_limits<double>::infinity());
                      if (arrays_.ids)
                        std::fill(object_.begin() + std::ptrdiff_t(r.begin()),
                                  object_.begin() + std::ptrdiff_t(r.end()), 0xFFFFFFFFu);
                      // Primitive ids and barycentrics are read only where an object was
                      // drawn, and written with it: not cleared.
                      if (arrays_.fragments)
                        std::fill(fragments_.begin() + std::ptrdiff_t(r.begin()),
                                  fragments_.begin() + std::ptrdiff_t(r.end()), 0u);
                    });
  block_max_.assign(size_t(blocks_x_) * size_t(blocks_y_), std::numeric_limits<double>::infinity());
  block_rejects_.assign(block_max_.size(), 0);
  block_empty_.resize(block_max_.size());
  fill_target_ = {depth_.data(),
                  object_.data(),
                  primitive_.data(),
                  bary_.data(),
                  fragments_.data(),
                  block_empty_.data(),
                  width_,
                  blocks_x_,
                  near_,
                  far_,
                  !arrays_.ids,
                  arrays_.barycentrics,
                  arrays_.fragments,
                  depth_format_};
  for (int by = 0; by < blocks_y_; ++by)
    for (int bx = 0; bx < blocks_x_; ++bx)
      block_empty_[size_t(by) * size_t(blocks_x_) + size_t(bx)] = uint16_t(
          (std::min(kBlock, width_ - bx * kBlock)) * (std::min(kBlock, height_ - by * kBlock)));
}

void DepthTarget::give_ids(PixelVector<uint32_t>& object, PixelVector<uint32_t>& primitive) {
  RVR_CHECK(arrays_.ids, "a target without ids has none to give");
  object.swap(object_);
  primitive.swap(primitive_);
  object_.clear();
  primitive_.clear();
  fill_target_.object = nullptr;
  fill_target_.primitive = nullptr;
}

size_t DepthTarget::bytes() const {
  return depth_.size() * sizeof(double) +
         (object_.size() + primitive_.size() + fragments_.size()) * sizeof(uint32_t) +
         bary_.size() * sizeof(float) + block_max_.size() * sizeof(double) +
         block_rejects_.size() * sizeof(uint32_t);
}

size_t DepthTarget::covered_pixels() const {
  size_t empty = 0;
  for (uint16_t n : block_empty_) empty += n;
  return size_t(width_) * size_t(height_) - empty;
}

void DepthTarget::leave_empty_count(size_t i) {
  const int x = int(i % size_t(width_)), y = int(i / size_t(width_));
  // Atomic: the rows of one 8-row band of blocks may be set by different threads.
  std::atomic_ref<uint16_t>(block_empty_[block_index(x, y)])
      .fetch_sub(1, std::memory_order_relaxed);
}

void DepthTarget::update_block_max(int bx, int by) {
  // While a pixel of the block is empty its farthest depth is +inf: nothing to scan.
  if (block_empty_[size_t(by) * size_t(blocks_x_) + size_t(bx)] > 0) return;
  const int x0 = bx * kBlock, y0 = by * kBlock;
  const int x1 = std::min(x0 + kBlock, width_), y1 = std::min(y0 + kBlock, height_);
  // Two doubles at a time (SSE2 is baseline x86-64). Depths are never NaN (drawn ones passed
  // the near/far test, the rest are +inf), so the order of the max does not matter.
  __m128d m2 = _mm_setzero_pd();
  double m = 0;
  for (int y = y0; y < y1; ++y) {
    const double* row = &depth_[size_t(y) * size_t(width_)];
    int x = x0;
    for (; x + 1 < x1; x += 2) m2 = _mm_max_pd(m2, _mm_loadu_pd(row + x));
    for (; x < x1; ++x) m = std::max(m, row[x]);
  }
  m = std::max({m, _mm_cvtsd_f64(m2), _mm_cvtsd_f64(_mm_unpackhi_pd(m2, m2))});
  block_max_[size_t(by) * size_t(blocks_x_) + size_t(bx)] = m;
}

void DepthTarget::draw_tile(int tx, int ty, const SetupTriangles* sub_chunks, const uint32_t* bin,
                            size_t count, TileCounters& counters) {
  RVR_DCHECK(tx >= 0 && tx < tiles_x_ && ty >= 0 && ty < tiles_y_, "tile (", tx, ", ", ty,
             ") outside the ", tiles_x_, "x", tiles_y_, " tiles");
  const int ox = tx * kTile, oy = ty * kTile;
  const int ex = std::min(ox + kTile, width_) - 1, ey = std::min(oy + kTile, height_) - 1;
  auto triangle = [&](size_t k) -> const SetupTriangle& {
    RVR_DCHECK((bin[k] & ((1u << kLocalBits) - 1)) < sub_chunks[bin[k] >> kLocalBits].size(),
               "a bin entry names a set-up triangle of its sub-chunk: ", bin[k]);
    return sub_chunks[bin[k] >> kLocalBits][bin[k] & ((1u << kLocalBits) - 1)];
  };
  // A bin's triangles lie scattered over the chunk (megabytes, beyond L2), and so do the pixels
  // they touch in the frame's buffers: both are fetched ahead, so that the misses overlap
  // instead of stalling one by one. Triangle k + kHotAhead: its hot line. Triangle
  // k + kColdAhead (whose hot line has arrived by then): its cold line and the depth and
  // fragment-count lines of the first two rows of its box in this tile.
  constexpr size_t kHotAhead = 8, kColdAhead = 4;
  auto fetch_rest = [&](const SetupTriangle& t) {
    __builtin_prefetch(reinterpret_cast<const char*>(&t) + 64);
    const int px = std::max(int(t.x0), ox), py = std::max(int(t.y0), oy);
    const int py1 = std::min({int(t.y1), ey, py + 1});
    for (int y = py; y <= py1; ++y) {
      const size_t i = size_t(y) * size_t(width_) + size_t(px);
      __builtin_prefetch(&depth_[i], 1);
      if (arrays_.fragments) __builtin_prefetch(&fragments_[i], 1);
    }
  };
  for (size_t k = 0; k < std::min(count, kHotAhead); ++k) __builtin_prefetch(&triangle(k));
  for (size_t k = 0; k < std::min(count, kColdAhead); ++k) fetch_rest(triangle(k));
  for (size_t k = 0; k < count; ++k) {
    if (k + kHotAhead < count) __builtin_prefetch(&triangle(k + kHotAhead));
    if (k + kColdAhead < count) fetch_rest(triangle(k + kColdAhead));
    const SetupTriangle& t = triangle(k);
    const int x0 = std::max(int(t.x0), ox), x1 = std::min(int(t.x1), ex);
    const int y0 = std::max(int(t.y0), oy), y1 = std::min(int(t.y1), ey);
    if (x0 > x1 || y0 > y1) continue;
    if (hiz_) {
      // The whole triangle at once: behind the farthest depth of every block it overlaps.
      double farthest = 0;
      for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
        for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx)
          farthest = std::max(farthest, block_max_[size_t(by) * size_t(blocks_x_) + size_t(bx)]);
      if (t.min_depth >= farthest) {
        for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
          for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx) {
            ++block_rejects_[size_t(by) * size_t(blocks_x_) + size_t(bx)];
            ++counters.blocks_rejected;
          }
        ++counters.triangles_rejected;
        continue;
      }
    }
    draw(t, x0, y0, x1, y1, counters);
  }
}

void DepthTarget::draw(const SetupTriangle& t, int x0, int y0, int x1, int y1,
                       TileCounters& counters) {
  // E_i(p) = (x[i+1]-x[i])*(py-y[i]) - (y[i+1]-y[i])*(px-x[i]) at pixel centres, in
  // sub-pixel units; a non-top-left edge needs E > 0, i.e. E - 1 >= 0 in integers.
  int64_t dx[3], dy[3], bias[3];
  for (int i = 0; i < 3; ++i) {
    const int n = (i + 1) % 3;
    dx[i] = int64_t(t.x[n]) - t.x[i];
    dy[i] = int64_t(t.y[n]) - t.y[i];
    bias[i] = t.top_left[i] ? 0 : 1;
  }
  auto edge = [&](int i, int x, int y) {
    const int64_t px = int64_t(x) * kSub + kSub / 2, py = int64_t(y) * kSub + kSub / 2;
    return dx[i] * (py - t.y[i]) - dy[i] * (px - t.x[i]) - bias[i];
  };
  // The pixels of one block (or of a small triangle's box), through the SIMD kernel: every
  // edge tested unless `full`.
  auto fill = [&](int bx0, int by0, int bx1, int by1, bool full) {
    FillTriangle f;
    for (int i = 0; i < 3; ++i) {
      f.row0[i] = edge(i, bx0, by0);
      f.step_x[i] = -dy[i] * kSub;
      f.step_y[i] = dx[i] * kSub;
      f.q0[i] = t.q0[size_t(i)];
      f.qa[i] = t.qa[size_t(i)];
      f.qb[i] = t.qb[size_t(i)];
    }
    f.ox = t.ox();
    f.oy = t.oy();
    f.object = t.object;
    f.primitive = t.primitive;
    FillResult r;
    kernels_->fill(f, fill_target_, bx0, by0, bx1, by1, full, r);
    counters.generated += r.generated;
    return r.drawn;
  };
  // A small triangle (at most 2x2 centres): those centres directly, no block classification
  // (draw_tile's whole-triangle hi-z test has been made); then its blocks' farthest depths.
  if (x1 - x0 < 2 && y1 - y0 < 2) {
    if (fill(x0, y0, x1, y1, false) && hiz_)
      for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
        for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx) update_block_max(bx, by);
    return;
  }
  // A box of at most a block's size (2x2 blocks at most) whose blocks hi-z keeps: the whole
  // box in one kernel pass, every edge tested. The block loop would give the same pixels and
  // counts (its outside blocks yield no fragment, its full ones the same fragments without the
  // tests), but in a kernel call per block after classifying each one's corners.
  if (x1 - x0 < kBlock && y1 - y0 < kBlock) {
    bool block_rejected = false;
    if (hiz_)
      for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
        for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx)
          block_rejected |= t.min_depth >= block_max_[size_t(by) * size_t(blocks_x_) + size_t(bx)];
    if (!block_rejected) {
      if (fill(x0, y0, x1, y1, false) && hiz_)
        for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
          for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx) update_block_max(bx, by);
      return;
    }
  }
  for (int by = y0 / kBlock; by <= y1 / kBlock; ++by) {
    for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx) {
      const int cx0 = std::max(x0, bx * kBlock), cx1 = std::min(x1, bx * kBlock + kBlock - 1);
      const int cy0 = std::max(y0, by * kBlock), cy1 = std::min(y1, by * kBlock + kBlock - 1);
      const size_t b = size_t(by) * size_t(blocks_x_) + size_t(bx);
      if (hiz_ && t.min_depth >= block_max_[b]) {
        ++block_rejects_[b];
        ++counters.blocks_rejected;
        continue;
      }
      // Edge functions are linear: their extremes over the block's centres are at its corners.
      bool full = true, outside = false;
      for (int i = 0; i < 3 && !outside; ++i) {
        const int64_t c[4] = {edge(i, cx0, cy0), edge(i, cx1, cy0), edge(i, cx0, cy1),
                              edge(i, cx1, cy1)};
        const int64_t lo = std::min({c[0], c[1], c[2], c[3]});
        const int64_t hi = std::max({c[0], c[1], c[2], c[3]});
        outside = hi < 0;
        full &= lo >= 0;
      }
      if (outside) continue;
      counters.blocks_full += full;
      if (fill(cx0, cy0, cx1, cy1, full) && hiz_) update_block_max(bx, by);
    }
  }
}

}  // namespace rvr::soft
