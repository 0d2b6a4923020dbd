// An allocator for softraster's large per-chunk arrays of set-up triangles: whole 2 MiB pages,
// marked for transparent huge pages (Linux's madvise mode grants them only when asked). The
// tile pass reads a chunk's triangles (megabytes) in scattered order; with 4 KiB pages nearly
// every one is a TLB miss, which also makes the prefetches of them late.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <new>
#include <utility>
#include <vector>

#include "rvr/core/pixel_memory.h"

namespace rvr::soft {

template <class T>
struct HugePageAllocator : DefaultInitConstruct {  // SetupTriangle has no member defaults
  using value_type = T;
  static constexpr size_t kPage = size_t(2) << 20;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) {}
  // Below half a page, plain memory: a huge page for a small scene's few triangles would only
  // cost its clearing (2 MiB at the first touch).
  static bool huge(size_t n) { return n * sizeof(T) >= kPage / 2; }
  // What allocate(n) takes.
  static size_t bytes_for(size_t n) {
    return huge(n) ? (n * sizeof(T) + kPage - 1) / kPage * kPage : n * sizeof(T);
  }
  // From the frame memory that is recycled between frames (pixel_memory.h): the next frame's
  // chunks reuse these pages instead of faulting and clearing fresh huge pages.
  T* allocate(size_t n) {
    // sizeof(T) is a multiple of alignof(T), so bytes is one of the alignment as it must be.
    // Frame memory of whole huge pages is asked for them (acquire_pixel_memory).
    const size_t align = huge(n) ? kPage : std::max<size_t>(alignof(T), 64);
    return static_cast<T*>(acquire_pixel_memory(bytes_for(n), align));
  }
  void deallocate(T* p, size_t n) noexcept {
    release_pixel_memory(p, bytes_for(n), huge(n) ? kPage : std::max<size_t>(alignof(T), 64));
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const {
    return true;
  }
  template <class U>
  bool operator!=(const HugePageAllocator<U>&) const {
    return false;
  }
};

}  // namespace rvr::soft
