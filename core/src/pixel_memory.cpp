#include "rvr/core/pixel_memory.h"

#include <cstdint>
#include <cstdlib>
#include <deque>
#include <iterator>
#include <memory>
#include <mutex>
#include <new>

#include "rvr/core/check.h"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace rvr {
namespace {

struct Block {
  void* p;
  size_t bytes, align;
};

// Released large blocks, oldest first. Never destroyed (a buffer in a static object may be
// released during exit, after a destroyed pool would have been gone); what it holds stays
// reachable, so leak checkers do not report it.
struct Pool {
  std::mutex mutex;
  std::deque<Block> free;
  size_t held = 0;
};

Pool& pool() {
  static Pool* p = new Pool;
  return *p;
}

// aligned_alloc wants a multiple of the alignment.
size_t rounded(size_t bytes, size_t align) {
  return (bytes + align - 1) / align * align;
}

// Marks the whole 2 MiB pages inside [p, p + bytes) for transparent huge pages (Linux's madvise
// mode grants them only when asked). A frame buffer is written and read in scattered tiles;
// with 4 KiB pages nearly every tile row is a TLB miss. A hint: without huge pages nothing
// changes.
void ask_for_huge_pages(void* p, size_t bytes) {
#if defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHuge = kHugePageBytes;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

}  // namespace

void* acquire_pixel_memory(size_t bytes, size_t align) {
  RVR_CHECK(align >= sizeof(void*) && (align & (align - 1)) == 0,
            "aligned_alloc takes a power-of-two alignment: ", align);
  const size_t size = rounded(bytes == 0 ? 1 : bytes, align);
  if (size >= kRecycledBytes) {
    Pool& pl = pool();
    std::lock_guard<std::mutex> lock(pl.mutex);
    // Newest first: its pages are the likeliest still to be in cache.
    for (auto it = pl.free.rbegin(); it != pl.free.rend(); ++it) {
      if (it->bytes != size || it->align != align) continue;
      void* p = it->p;
      RVR_DCHECK(pl.held >= size, "the pool holds every block it lists");
      pl.held -= size;
      pl.free.erase(std::next(it).base());
      return p;
    }
  }
  void* p = std::aligned_alloc(align, size);
  if (!p) throw std::bad_alloc();
  if (size >= kHugePageBytes) ask_for_huge_pages(p, size);  // a recycled block was asked already
  return p;
}

void release_pixel_memory(void* p, size_t bytes, size_t align) noexcept {
  if (!p) return;
  const size_t size = rounded(bytes == 0 ? 1 : bytes, align);
  if (size < kRecycledBytes || size > kRecycleLimitBytes) {
    std::free(p);
    return;
  }
  Pool& pl = pool();
  std::lock_guard<std::mutex> lock(pl.mutex);
  pl.free.push_back({p, size, align});
  pl.held += size;
  while (pl.held > kRecycleLimitBytes) {
    std::free(pl.free.front().p);
    pl.held -= pl.free.front().bytes;
    pl.free.pop_front();
  }
}

size_t recycled_pixel_bytes() {
  Pool& pl = pool();
  std::lock_guard<std::mutex> lock(pl.mutex);
  return pl.held;
}

}  // namespace rvr
