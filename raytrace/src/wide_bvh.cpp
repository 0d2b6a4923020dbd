// Collapsing the binary SAH tree into 8-wide nodes and 4-triangle SoA leaf blocks.
#include "rvr/raytrace/wide_bvh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <glm/glm.hpp>
#include <memory>
#include <string>

#include "rvr/core/check.h"
#include "rvr/core/ray.h"

namespace rvr {
namespace {

// For the SAH of the binary tree the wide one is made from: a wide node visit tests eight boxes
// at once, so it costs about as much as testing one 4-triangle block. Trace speed hardly depends
// on this cost or on the leaf size (bench/JOURNAL.md); cost 1 with leaves of up to 8 triangles
// takes the least memory.
constexpr float kWideTraversalCost = 1.0f;

class Collapser {
 public:
  Collapser(const Bvh& binary, const std::vector<TrianglePrecomputed>& triangles,
            TraversalVector<WideNode>& nodes, TraversalVector<TriangleBlock>& blocks,
            WideBvhStats& stats)
      : binary_(binary.nodes()),
        order_(binary.primitive_order()),
        triangles_(triangles),
        nodes_(nodes),
        blocks_(blocks),
        stats_(stats) {}

  // The reference to the wide subtree of binary node `b`, `depth` inner levels below the root.
  uint32_t collapse(uint32_t b, size_t depth) {
    const BvhNode& node = binary_[b];
    if (node.count > 0) return make_leaf(node);
    stats_.max_depth = std::max(stats_.max_depth, depth);
    // Gather up to eight children by opening the inner child of largest area.
    uint32_t children[kWideBvhWidth] = {b + 1, node.offset};
    int n = 2;
    while (n < kWideBvhWidth) {
      int best = -1;
      float best_area = -1.0f;
      for (int i = 0; i < n; ++i) {
        const BvhNode& c = binary_[children[i]];
        if (c.count > 0) continue;
        float area = box_of(c).surface_area();
        if (area > best_area) best = i, best_area = area;
      }
      if (best < 0) break;
      uint32_t opened = children[best];
      children[best] = opened + 1;
      children[n++] = binary_[opened].offset;
    }
    RVR_CHECK(n >= 2 && n <= kWideBvhWidth, "a wide node has 2 to 8 children: ", n);
    uint32_t index = uint32_t(nodes_.size());
    RVR_CHECK((index & kLeafFlag) == 0 && index != kEmptyTree,
              "an inner node's index must not look like a leaf reference: ", index);
    nodes_.push_back(empty_node());
    stats_.child_slots += size_t(n);
    for (int i = 0; i < n; ++i) {
      Aabb box = box_of(binary_[children[i]]);
      uint32_t ref = collapse(children[i], depth + 1);
      WideNode& w = nodes_[index];  // after the recursion: push_back may have moved it
      for (int a = 0; a < 3; ++a) {
        w.bounds[2 * a][i] = box.lo[a];
        w.bounds[2 * a + 1][i] = box.hi[a];
      }
      w.child[i] = ref;
    }
    return index;
  }

  // Triangles in the leaves made so far: all of them once the root is collapsed.
  size_t leaf_triangles() const { return leaf_triangles_; }

 private:
  static Aabb box_of(const BvhNode& n) { return Aabb{n.lo, n.hi}; }

  static WideNode empty_node() {
    WideNode w;
    for (int i = 0; i < kWideBvhWidth; ++i) {
      for (int a = 0; a < 3; ++a) {
        w.bounds[2 * a][i] = INFINITY;
        w.bounds[2 * a + 1][i] = -INFINITY;
      }
      w.child[i] = kEmptyTree;
    }
    return w;
  }

  uint32_t make_leaf(const BvhNode& node) {
    uint32_t first = uint32_t(blocks_.size());
    uint32_t count = node.count;
    RVR_CHECK(count >= 1 && count <= uint32_t(kMaxLeafTriangles) && count < (1u << kLeafCountBits),
              "a leaf's triangle count must fit its reference's ", kLeafCountBits,
              " bits: ", count);
    RVR_CHECK(first + (count + kTriangleBlock - 1) / kTriangleBlock <= kMaxBlocks,
              "WideBvh::build refuses scenes whose blocks overflow the leaf reference: block ",
              first);
    for (uint32_t k = 0; k < count; k += kTriangleBlock) {
      TriangleBlock block{};
      for (int lane = 0; lane < kTriangleBlock; ++lane) {
        block.primitive[lane] = kUnusedLane;
        if (k + uint32_t(lane) >= count) continue;  // zero edges: determinant 0, never hit
        uint32_t p = order_[node.offset + k + uint32_t(lane)];
        const TrianglePrecomputed& t = triangles_[p];
        for (int a = 0; a < 3; ++a) {
          block.v0[a][lane] = t.v0[a];
          block.e1[a][lane] = t.e1[a];
          block.e2[a][lane] = t.e2[a];
        }
        block.primitive[lane] = p;
      }
      blocks_.push_back(block);
    }
    stats_.leaves++;
    leaf_triangles_ += count;
    return kLeafFlag | first << kLeafCountBits | count;
  }

  const TraversalVector<BvhNode>& binary_;
  const std::vector<uint32_t>& order_;
  const std::vector<TrianglePrecomputed>& triangles_;
  TraversalVector<WideNode>& nodes_;
  TraversalVector<TriangleBlock>& blocks_;
  WideBvhStats& stats_;
  size_t leaf_triangles_ = 0;  // over all leaves made so far
};

}  // namespace

Expected<WideBvh> WideBvh::build(const std::vector<TrianglePrecomputed>& triangles) {
  auto start = std::chrono::steady_clock::now();
  WideBvh w;
  w.stats_.triangles = triangles.size();
  if (triangles.empty()) return w;
  // Every leaf needs at most two blocks; the block index must fit its reference.
  if (triangles.size() / kTriangleBlock + 1 >= kMaxBlocks / 2)
    return bad_input("the wide BVH holds at most " + std::to_string(kMaxBlocks) +
                     " triangle blocks; this scene has " + std::to_string(triangles.size()) +
                     " triangles (use --accel bvh2)");
  std::vector<Aabb> bounds(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    const TrianglePrecomputed& t = triangles[i];
    bounds[i].grow(t.v0);
    bounds[i].grow(t.v0 + t.e1);
    bounds[i].grow(t.v0 + t.e2);
  }
  BvhBuildOptions options;
  options.max_leaf_size = kMaxLeafTriangles;
  options.leaf_block = kTriangleBlock;
  options.traversal_cost = kWideTraversalCost;
  Bvh binary = Bvh::build(bounds, options);
  w.stats_.binary_seconds = binary.stats().seconds;
  w.stats_.binary_sah_cost = binary.stats().sah_cost;

  // The blocks exactly (so they are never copied, by growth or by shrink_to_fit); the nodes
  // roughly (each has two to eight children).
  size_t blocks = 0;
  for (const BvhNode& node : binary.nodes())
    blocks += (size_t(node.count) + kTriangleBlock - 1) / kTriangleBlock;
  w.nodes_.reserve(binary.stats().nodes / 4 + 1);
  w.blocks_.reserve(blocks);
  Collapser collapser(binary, triangles, w.nodes_, w.blocks_, w.stats_);
  w.root_ = collapser.collapse(0, 0);
  RVR_CHECK(w.stats_.max_depth < 64,
            "the traversal stacks (wide_kernels.inl) hold 64 inner levels; depth ",
            w.stats_.max_depth);
  RVR_CHECK(collapser.leaf_triangles() == triangles.size(),
            "every triangle lies in exactly one leaf: ", collapser.leaf_triangles(), " of ",
            triangles.size());
  RVR_CHECK(w.nodes_.size() + w.stats_.leaves - 1 == w.stats_.child_slots,
            "every node but the root fills one child slot: ", w.nodes_.size(), " nodes, ",
            w.stats_.leaves, " leaves, ", w.stats_.child_slots, " slots");
  RVR_CHECK(w.blocks_.size() == blocks, "the leaves fill the blocks counted: ", w.blocks_.size(),
            " of ", blocks);
  w.nodes_.shrink_to_fit();
  w.stats_.nodes = w.nodes_.size();
  w.stats_.blocks = w.blocks_.size();
  w.stats_.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return w;
}

bool recheck_triangle_near_edge(const KernelRay& ray, const float tri[9], float t_limit,
                                KernelHit& hit) {
  Ray r;
  r.origin = {ray.origin[0], ray.origin[1], ray.origin[2]};
  r.dir = {ray.dir[0], ray.dir[1], ray.dir[2]};
  r.tmin = ray.tmin;
  r.tmax = std::nextafter(t_limit, INFINITY);  // t_limit itself is allowed
  TrianglePrecomputed t{
      {tri[0], tri[1], tri[2]}, {tri[3], tri[4], tri[5]}, {tri[6], tri[7], tri[8]}};
  TriangleHit h;
  if (!intersect_triangle_mt_double(r, t, h)) return false;
  hit.t = h.t;
  hit.u = h.u;
  hit.v = h.v;
  return true;
}

}  // namespace rvr
