// A tile of rays from one origin walked through the binary BVH together: the slab test of up to
// 64 rays at a time (PacketBoxData) and traverse_packet, which visits a node while any ray of the
// packet enters it. Each ray's own slab test is RayBoxData's arithmetic, operation for operation,
// so a ray enters a box here exactly when RayBoxData says it does.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "rvr/raytrace/bvh.h"

namespace rvr {

struct PacketBoxData {
  static constexpr int kMaxRays = 64;
  float origin[3];
  int count = 0;
  float t_min = 0.0f;
  alignas(64) float inv_dir[3][kMaxRays];
  alignas(64) bool neg[3][kMaxRays];
  // Rays k in [0, ray_count): origin + t * (dir[0][k], dir[1][k], dir[2][k]), t in (t_min, ...).
  PacketBoxData(const float ray_origin[3], const float* const dir[3], int ray_count,
                float ray_t_min)
      : count(ray_count), t_min(ray_t_min) {
    for (int a = 0; a < 3; ++a) {
      origin[a] = ray_origin[a];
      for (int k = 0; k < count; ++k) {
        inv_dir[a][k] = 1.0f / dir[a][k];
        neg[a][k] = inv_dir[a][k] < 0.0f;
      }
      // Lanes past the count hold copies of ray 0 (never in a mask), so loops run full width.
      for (int k = count; k < kMaxRays; ++k) {
        inv_dir[a][k] = count > 0 ? inv_dir[a][0] : 0.0f;
        neg[a][k] = count > 0 && neg[a][0];
      }
    }
  }
  uint64_t all() const { return count == 64 ? ~uint64_t(0) : (uint64_t(1) << count) - 1; }

  // The rays of `active` that enter box n before their t_max[k] (kMaxRays entries), each by
  // RayBoxData::hits's operations in its order (NaN slab values pass as there).
  uint64_t hits(const BvhNode& n, const float* t_max, uint64_t active) const {
    bool entered[kMaxRays];
    for (int k = 0; k < kMaxRays; ++k) {
      const float tx0 = ((neg[0][k] ? n.hi.x : n.lo.x) - origin[0]) * inv_dir[0][k];
      const float tx1 = ((neg[0][k] ? n.lo.x : n.hi.x) - origin[0]) * inv_dir[0][k];
      const float ty0 = ((neg[1][k] ? n.hi.y : n.lo.y) - origin[1]) * inv_dir[1][k];
      const float ty1 = ((neg[1][k] ? n.lo.y : n.hi.y) - origin[1]) * inv_dir[1][k];
      const float tz0 = ((neg[2][k] ? n.hi.z : n.lo.z) - origin[2]) * inv_dir[2][k];
      const float tz1 = ((neg[2][k] ? n.lo.z : n.hi.z) - origin[2]) * inv_dir[2][k];
      const float t0 = std::max(std::max(std::max(t_min, tx0), ty0), tz0);
      const float t1 =
          std::min(std::min(std::min(t_max[k], tx1), ty1), tz1) * RayBoxData::kExitWiden;
      entered[k] = t0 <= t1;
    }
    uint64_t mask = 0;
    for (int k = 0; k < kMaxRays; ++k) mask |= uint64_t(entered[k]) << k;
    return mask & active;
  }
};

// Bvh::traverse for the rays of a packet at once, each with its own t_max[k] (kMaxRays entries;
// those past the count are never read for a decision): a node is visited while any ray of the
// packet enters its box. A ray visits a node when it entered the node's parent, as in
// traverse(), and is tested at a leaf whose box it enters, so it finds the same hits; visiting
// in another order, its t_max may shrink at other times, so its counts can differ a little from
// traverse()'s. leaf(first_slot, count, rays) tests the primitives in those slots for the rays
// of bit mask `rays` and may lower their t_max. counters[k] counts ray k's steps when kCount.
template <bool kCount, class PacketLeafFn>
void traverse_packet(const Bvh& bvh, const PacketBoxData& rays, float* t_max, PacketLeafFn&& leaf,
                     TraversalCounters* counters) {
  if (bvh.empty() || rays.count == 0) return;
  struct Entry {
    uint32_t node;
    uint64_t rays;  // the rays that entered its parent: those that visit it
  };
  Entry stack[Bvh::kStackSize];
  int top = 0;
  Entry current{0, rays.all()};
  for (;;) {
    const BvhNode& node = bvh.nodes()[current.node];
    if (kCount)
      for (uint64_t m = current.rays; m != 0; m &= m - 1)
        ++counters[__builtin_ctzll(m)].nodes_visited;
    const uint64_t entered = rays.hits(node, t_max, current.rays);
    if (entered != 0 && node.count > 0) {
      if (kCount)
        for (uint64_t m = entered; m != 0; m &= m - 1)
          counters[__builtin_ctzll(m)].primitive_tests += node.count;
      leaf(node.offset, uint32_t(node.count), entered);
    } else if (entered != 0) {
      // Near child first as the first ray entering sees it (any order finds the same hits).
      const uint32_t first = current.node + 1, second = node.offset;
      const bool second_nearer = rays.neg[node.axis][__builtin_ctzll(entered)];
      stack[top++] = {second_nearer ? first : second, entered};
      current = {second_nearer ? second : first, entered};
      continue;
    }
    if (top == 0) return;
    current = stack[--top];
  }
}

}  // namespace rvr
