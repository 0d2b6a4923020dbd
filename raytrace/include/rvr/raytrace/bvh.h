// The binary bounding volume hierarchy ("bvh2", the chapter's early rejection in its plainest
// form): binned-SAH builder (bvh.cpp) apart from traversal (here, inline), flattened into
// 32-byte nodes in depth-first order, traversed near child first with a fixed stack. It knows
// only boxes; what a leaf's primitives are is the caller's business. The wide BVH (wide_bvh.h)
// is collapsed from this tree.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <glm/glm.hpp>
#include <new>
#include <vector>

#include "rvr/core/ray.h"

namespace rvr {

struct Aabb {
  glm::vec3 lo{INFINITY};
  glm::vec3 hi{-INFINITY};

  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x; }
  glm::vec3 centroid() const { return 0.5f * (lo + hi); }
  float surface_area() const {
    if (empty()) return 0.0f;
    glm::vec3 d = hi - lo;
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

// Interior: count == 0, the first child follows at index + 1, the second is at `offset`.
// Leaf: count > 0 primitives starting at `offset` in Bvh::primitive_order().
struct alignas(32) BvhNode {
  glm::vec3 lo;
  uint32_t offset;
  glm::vec3 hi;
  uint16_t count;
  uint8_t axis;  // split axis of an interior node: decides which child is near
  uint8_t pad;
};
static_assert(sizeof(BvhNode) == 32, "BVH nodes are 32 bytes");

// madvise(MADV_HUGEPAGE); a no-op where that does not exist. Failure only costs speed.
void advise_huge_pages(void* p, size_t bytes);

// Allocator for the arrays traversal walks (nodes, leaf-ordered triangles): 64-byte aligned,
// and arrays of 2 MiB or more on transparent huge pages where the kernel offers them only on
// request (madvise mode, as here), as Embree does for its own. With 4 KiB pages a 100k-triangle
// tree spans ~2,000 pages and traversal pays TLB misses, so its speed would depend on where
// malloc happened to put it.
template <class T>
struct TraversalAllocator {
  using value_type = T;
  static constexpr size_t kHugePage = size_t(2) << 20;
  TraversalAllocator() = default;
  template <class U>
  TraversalAllocator(const TraversalAllocator<U>&) {}
  T* allocate(size_t n) {
    size_t bytes = std::max<size_t>(n * sizeof(T), 64);
    size_t alignment = bytes >= kHugePage ? kHugePage : 64;
    bytes = (bytes + alignment - 1) / alignment * alignment;
    void* p = std::aligned_alloc(alignment, bytes);
    if (!p) throw std::bad_alloc();
    if (alignment == kHugePage) advise_huge_pages(p, bytes);
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t) { std::free(p); }
  template <class U>
  bool operator==(const TraversalAllocator<U>&) const {
    return true;
  }
  template <class U>
  bool operator!=(const TraversalAllocator<U>&) const {
    return false;
  }
};

template <class T>
using TraversalVector = std::vector<T, TraversalAllocator<T>>;

struct BvhBuildOptions {
  int max_leaf_size = 8;
  // A node visit against one primitive test, in the SAH. Lower costs give smaller leaves and
  // more nodes (more memory per triangle); 3 is where the binary tree's trace speed (BM_Trace)
  // is best for the memory it takes (BM_Build reports both; bench/JOURNAL.md has the sweep).
  float traversal_cost = 3.0f;
  // Leaves are tested this many primitives at a time (SIMD blocks): the SAH counts a leaf of n
  // as ceil(n / leaf_block) tests, as Embree's builders do for their 4-triangle leaves.
  int leaf_block = 1;
};

struct BvhBuildStats {
  size_t primitives = 0;
  size_t nodes = 0;
  size_t leaves = 0;
  size_t max_depth = 0;
  double sah_cost = 0.0;  // expected cost per ray: traversal 1, primitive test 1
  double seconds = 0.0;
};

struct TraversalCounters {
  uint64_t nodes_visited = 0;
  uint64_t primitive_tests = 0;
};

class Bvh {
 public:
  static constexpr int kMaxLeafSize = 8;
  static constexpr int kStackSize = 64;

  // Builds over primitives given by their bounds; empty input gives an empty tree.
  static Bvh build(const std::vector<Aabb>& primitive_bounds, const BvhBuildOptions& options = {});

  const TraversalVector<BvhNode>& nodes() const { return nodes_; }
  // Leaf slots -> primitive index given to build().
  const std::vector<uint32_t>& primitive_order() const { return order_; }
  const BvhBuildStats& stats() const { return stats_; }
  bool empty() const { return nodes_.empty(); }

  // Visits the leaves whose boxes the ray enters before t_max, near child first.
  // leaf(first_slot, count, t_max) tests the primitives in slots [first, first + count),
  // may lower t_max to the nearest hit so far, and returns true to stop (any-hit queries).
  template <class LeafFn>
  void traverse(const Ray& ray, float& t_max, LeafFn&& leaf, TraversalCounters& counters) const;

 private:
  TraversalVector<BvhNode> nodes_;
  std::vector<uint32_t> order_;
  BvhBuildStats stats_;
};

// Slab test against a node box with precomputed reciprocal direction.
struct RayBoxData {
  // Widen the exit a little (pbrt's 1 + 2*gamma(3)) so rounding never loses a hit.
  static constexpr float kExitWiden = 1.0000004f;
  glm::vec3 origin, inv_dir;
  int neg[3];
  explicit RayBoxData(const Ray& ray) : origin(ray.origin), inv_dir(1.0f / ray.dir) {
    for (int a = 0; a < 3; ++a) neg[a] = inv_dir[a] < 0.0f;
  }
  bool hits(const BvhNode& n, float t_min, float t_max) const {
    // A ray lying in a slab's plane (dir = +-0, origin on the face) gives 0 * inf = NaN: that
    // slab does not constrain it. std::max(a, b) and std::min(a, b) return a when b is NaN (and
    // pass a NaN a through), so the slab values go second and t_min / t_max start the chains.
    const glm::vec3* b[2] = {&n.lo, &n.hi};
    float tx0 = ((*b[neg[0]]).x - origin.x) * inv_dir.x;
    float tx1 = ((*b[1 - neg[0]]).x - origin.x) * inv_dir.x;
    float ty0 = ((*b[neg[1]]).y - origin.y) * inv_dir.y;
    float ty1 = ((*b[1 - neg[1]]).y - origin.y) * inv_dir.y;
    float tz0 = ((*b[neg[2]]).z - origin.z) * inv_dir.z;
    float tz1 = ((*b[1 - neg[2]]).z - origin.z) * inv_dir.z;
    float t0 = std::max(std::max(std::max(t_min, tx0), ty0), tz0);
    float t1 = std::min(std::min(std::min(t_max, tx1), ty1), tz1) * kExitWiden;
    return t0 <= t1;
  }
};

template <class LeafFn>
void Bvh::traverse(const Ray& ray, float& t_max, LeafFn&& leaf, TraversalCounters& counters) const {
  if (nodes_.empty()) return;
  RayBoxData box(ray);
  uint32_t stack[kStackSize];
  int top = 0;
  uint32_t current = 0;
  for (;;) {
    const BvhNode& node = nodes_[current];
    ++counters.nodes_visited;
    if (box.hits(node, ray.tmin, t_max)) {
      if (node.count > 0) {
        counters.primitive_tests += node.count;
        if (leaf(node.offset, uint32_t(node.count), t_max)) return;
        if (top == 0) return;
        current = stack[--top];
      } else if (box.neg[node.axis]) {  // second child is nearer
        stack[top++] = current + 1;
        current = node.offset;
      } else {
        stack[top++] = node.offset;
        current = current + 1;
      }
    } else {
      if (top == 0) return;
      current = stack[--top];
    }
  }
}

}  // namespace rvr
