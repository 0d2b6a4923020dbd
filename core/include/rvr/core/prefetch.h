// A software prefetch: asks the cache for the line holding an address ahead of a load that would
// miss, so that the misses of a batch overlap instead of stalling one at a time.
#pragma once

#include <cstddef>

namespace rvr {

// Below this many triangles a scene's per-triangle shading data (vertex indices, vertices,
// normals, the tracer's precomputed edges: about 100 bytes a triangle) stays in a core's L2
// cache, and fetching it ahead would be work for nothing; both loop orders skip it there alike.
constexpr size_t kFetchAheadTriangles = size_t(1) << 14;

// An asm statement rather than __builtin_prefetch: GCC 12 deletes a builtin prefetch whose loop
// does nothing else but test a condition (the shape of a fetch-ahead pass over a batch), and the
// statement is never deleted. Any address may be given: a prefetch never faults.
inline void prefetch(const void* p) {
  asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(p)));
}

}  // namespace rvr
