// The wide BVH ("bvh", the default): the binned-SAH binary tree collapsed into 8-wide nodes by
// opening, at every node, the child of largest surface area until eight children are gathered
// (as Embree's builders do), with leaves of 1..8 triangles stored in 4-wide SoA blocks. Built
// here in baseline code; traversed by the SIMD kernels of the instruction set chosen at run time
// (simd_kernels.h).
#pragma once

#include <stddef.h>

#include <cstdint>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/intersect.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

struct WideBvhStats {
  size_t triangles = 0;
  size_t nodes = 0;        // wide nodes
  size_t leaves = 0;       // leaf references
  size_t blocks = 0;       // triangle blocks
  size_t child_slots = 0;  // child slots in use, over all nodes (fill = child_slots / 8 nodes)
  size_t max_depth = 0;    // inner levels below the root
  double binary_sah_cost = 0.0;
  double seconds = 0.0;         // whole build
  double binary_seconds = 0.0;  // of which the binary SAH tree
};

class WideBvh {
 public:
  // Over triangles whose reported primitive index is their position in `triangles`. Fails only
  // when the tree would not fit its 32-bit references (over 2^29 triangles).
  static Expected<WideBvh> build(const std::vector<TrianglePrecomputed>& triangles);

  WideBvhView view() const {
    return {nodes_.data(), blocks_.data(), root_, uint32_t(stats_.max_depth)};
  }
  const TraversalVector<WideNode>& nodes() const { return nodes_; }
  const TraversalVector<TriangleBlock>& blocks() const { return blocks_; }
  uint32_t root() const { return root_; }
  const WideBvhStats& stats() const { return stats_; }
  bool empty() const { return root_ == kEmptyTree; }
  size_t bytes() const {
    return nodes_.size() * sizeof(WideNode) + blocks_.size() * sizeof(TriangleBlock);
  }

  static bool is_leaf(uint32_t ref) { return (ref & kLeafFlag) != 0; }
  static uint32_t leaf_first_block(uint32_t ref) { return (ref & ~kLeafFlag) >> kLeafCountBits; }
  static uint32_t leaf_triangles(uint32_t ref) { return ref & ((1u << kLeafCountBits) - 1); }

 private:
  TraversalVector<WideNode> nodes_;
  TraversalVector<TriangleBlock> blocks_;
  uint32_t root_ = kEmptyTree;
  WideBvhStats stats_;
};

}  // namespace rvr
