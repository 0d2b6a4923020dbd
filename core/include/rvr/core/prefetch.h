// A software prefetch: asks the cache for the line holding an address ahead of a load that would
// miss, so that the misses of a batch overlap instead of stalling one at a time.
#pragma once

namespace rvr {

// An asm statement rather than __builtin_prefetch: GCC 12 deletes a builtin prefetch whose loop
// does nothing else but test a condition (the shape of a fetch-ahead pass over a batch), and the
// statement is never deleted. Any address may be given: a prefetch never faults.
inline void prefetch(const void* p) {
  asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(p)));
}

}  // namespace rvr
