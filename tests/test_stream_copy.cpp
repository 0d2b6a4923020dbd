// stream_copy (rvr/core/stream_copy.h) writes exactly the bytes memcpy writes, for every
// alignment of the destination and source and every length around the cache line's ragged
// head and tail, and nothing beside them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "rvr/core/stream_copy.h"

using namespace rvr;

namespace {

// A byte pattern no shifted copy of itself reproduces within a few lines.
uint8_t pattern(size_t i) {
  return uint8_t((i * 131u + (i >> 8) * 7u + 17u) & 0xFFu);
}

}  // namespace

TEST(StreamCopy, WritesExactlyTheSourceBytesAtEveryAlignmentAndLength) {
  constexpr size_t kGuard = 128, kMaxLength = 64 * 6 + 1;
  std::vector<uint8_t> source(kMaxLength + 64);
  for (size_t i = 0; i < source.size(); ++i) source[i] = pattern(i);
  // A 64-byte-aligned arena: destination offset d puts the copy at every place in a line.
  std::vector<uint8_t> storage(kGuard + kMaxLength + 64 + kGuard + 64);
  uint8_t* arena = storage.data() + (64 - reinterpret_cast<uintptr_t>(storage.data()) % 64) % 64;
  const size_t arena_bytes = kGuard + kMaxLength + 64 + kGuard;
  for (size_t d = 0; d < 64; d += 3)
    for (size_t s = 0; s < 64; s += 13)
      for (size_t n = 0; n <= kMaxLength; n += (n < 140 ? 1 : 29)) {
        std::fill(arena, arena + arena_bytes, uint8_t(0xEE));
        stream_copy(arena + kGuard + d, source.data() + s, n);
        stream_fence();
        for (size_t i = 0; i < arena_bytes; ++i) {
          const bool inside = i >= kGuard + d && i < kGuard + d + n;
          const uint8_t want = inside ? source[s + (i - kGuard - d)] : uint8_t(0xEE);
          ASSERT_EQ(arena[i], want) << "destination offset " << d << ", source offset " << s
                                    << ", length " << n << ", byte " << i;
        }
      }
}

TEST(StreamCopy, CopiesAFrameSizedBufferWhole) {
  const size_t n = (size_t(1) << 20) + 12;  // beyond any cache line count, ragged at the end
  std::vector<uint8_t> from(n), to(n + 1, 0);
  for (size_t i = 0; i < n; ++i) from[i] = pattern(i);
  stream_copy(to.data() + 1, from.data(), n);
  stream_fence();
  EXPECT_EQ(to[0], 0);
  EXPECT_TRUE(std::equal(from.begin(), from.end(), to.begin() + 1));
}
