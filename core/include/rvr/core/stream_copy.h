// Copies into a frame buffer that is written once and not read again by the writer: the whole
// cache lines of the destination go with streaming (non-temporal) stores, which skip reading
// the line before writing it and do not evict the writer's working set. A frame's buffers are
// tens of MB, far beyond any cache; an ordinary store first reads each of their lines from
// memory. The ragged ends (less than a line) are ordinary stores, as a partly written
// streaming line costs more than the read it saves.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rvr {

inline void stream_copy(void* to, const void* from, size_t bytes) {
#if defined(__SSE2__)
  constexpr size_t kLine = 64;
  auto* d = static_cast<char*>(to);
  const auto* s = static_cast<const char*>(from);
  const size_t head = std::min(bytes, (kLine - reinterpret_cast<uintptr_t>(d) % kLine) % kLine);
  std::memcpy(d, s, head);
  d += head;
  s += head;
  bytes -= head;
  for (; bytes >= kLine; bytes -= kLine, d += kLine, s += kLine)
    for (size_t k = 0; k < kLine; k += 16)
      _mm_stream_si128(reinterpret_cast<__m128i*>(d + k),
                       _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + k)));
  std::memcpy(d, s, bytes);
#else
  std::memcpy(to, from, bytes);
#endif
}

// Orders this thread's streaming stores before any store after it: called once a thread has
// finished a piece of a frame, before another thread may read it.
inline void stream_fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

}  // namespace rvr
