// Memory for whole-frame buffers, recycled between frames. A frame's buffers are tens of MB;
// taken fresh from the system every frame, each of their pages faults and is cleared by the
// kernel on first touch, a large share of a softraster frame's time. Blocks of at least
// kRecycledBytes that are released are kept (up to kRecycleLimitBytes in all, oldest freed first
// beyond that) and handed out again for a request of the same size: the next frame's buffers reuse
// the last frame's pages, as a GPU driver reuses its framebuffers. Contents of a recycled block are
// whatever was there: only buffers whose every element is written before being read use this
// (PixelVector).
#pragma once

#include <cstddef>
#include <new>
#include <utility>

namespace rvr {

constexpr size_t kRecycledBytes = size_t(1) << 20;
// Blocks this large are asked for transparent huge pages (the whole such pages inside them), so
// every renderer's frame buffers get the same pages.
constexpr size_t kHugePageBytes = size_t(2) << 20;
constexpr size_t kRecycleLimitBytes = size_t(256) << 20;

// Aligned to `align` (a power of two, at least 64); throws std::bad_alloc when the system has no
// memory left.
void* acquire_pixel_memory(size_t bytes, size_t align = 64);
// `bytes` and `align` as given to acquire_pixel_memory.
void release_pixel_memory(void* p, size_t bytes, size_t align = 64) noexcept;
// Bytes held for recycling now (at most kRecycleLimitBytes).
size_t recycled_pixel_bytes();

// For allocators of frame memory: resize() default-initialises (no value-initialising pass
// over elements their writer is about to overwrite).
struct DefaultInitConstruct {
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

}  // namespace rvr
