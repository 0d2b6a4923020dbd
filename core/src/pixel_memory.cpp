#include "rvr/core/pixel_memory.h"

#include <cstdlib>
#include <deque>
#include <iterator>
#include <memory>
#include <mutex>
#include <new>

#include "rvr/core/check.h"

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
