// Binned SAH builder (as in pbrt-v4 and Embree): at each node, bin primitive centroids into
// kBins slots per axis, sweep the bins for the split of least surface-area cost, and stop
// when a leaf is cheaper than any split. Nodes come out in depth-first order.
#include "rvr/raytrace/bvh.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <utility>

#include "rvr/core/check.h"

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace rvr {

void advise_huge_pages(void* p, size_t bytes) {
#ifdef MADV_HUGEPAGE
  madvise(p, bytes, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

namespace {

// Bins per axis of the SAH sweep: as in Embree's binned builder; more bins find no cheaper
// splits worth the extra binning work (bench/JOURNAL.md).
constexpr int kBins = 16;
constexpr float kIntersectCost = 1.0f;
// Past this depth splits are object medians, so the depth (and the traversal stack) stays
// bounded whatever the input.
constexpr size_t kMedianDepth = 32;

// A primitive's bounds and index, partitioned in place as the tree is built (as Embree's
// PrimRef): every pass over a node's primitives reads memory in order, where an index array into
// the input would jump around it at every level.
struct PrimRef {  // 32 bytes
  glm::vec3 lo;
  uint32_t id;
  glm::vec3 hi;
  uint32_t pad;
  glm::vec3 centroid2() const { return lo + hi; }  // twice the centroid: no multiply needed
};

// A node to build: its primitives, bounds and the bounds of their (doubled) centroids, computed
// by the parent's partition pass.
struct BuildTask {
  uint32_t begin, end;  // range in the PrimRef array
  uint32_t parent;      // node whose `offset` must point here (second children), or ~0
  size_t depth;
  Aabb box, centroid_box;
};

struct Split {
  int axis = -1;
  int bin = 0;  // primitives in bins [0, bin] go left
  float cost = INFINITY;
};

// Four floats as one value of the compiler's generic vectors (GCC and Clang vector extensions):
// baseline code, so plain SSE2 on every x86-64; + - * < ?: and & work lane by lane.
typedef float Row4 __attribute__((vector_size(16)));
typedef int32_t Int4 __attribute__((vector_size(16)));

// A PrimRef's two rows of four lanes: lo with the bits of id, hi with those of pad.
void rows_of(const PrimRef& r, Row4& lo, Row4& hi) {
  static_assert(sizeof(PrimRef) == 2 * sizeof(Row4), "a PrimRef is two rows of four lanes");
  std::memcpy(&lo, &r, sizeof lo);
  std::memcpy(&hi, reinterpret_cast<const char*>(&r) + sizeof lo, sizeof hi);
}

// Twice the centroid (lo + hi, as centroid2) in lanes x, y, z; lane 3 is 0 (the id's bits are
// cleared first: added as floats they could be denormals, which some CPUs add slowly).
Row4 centroid2_row(Row4 lo, Row4 hi) {
  const Int4 xyz = {-1, -1, -1, 0};
  return Row4(Int4(lo) & xyz) + Row4(Int4(hi) & xyz);
}

// A box as two rows of four lanes (x, y, z and one never read), grown by a PrimRef's rows with
// one vector min and one vector max. Its fourth lanes only take min and max of the bits of id and
// pad, no arithmetic.
struct Box4 {
  Row4 lo = {INFINITY, INFINITY, INFINITY, INFINITY};
  Row4 hi = {-INFINITY, -INFINITY, -INFINITY, -INFINITY};
  void grow(Row4 ref_lo, Row4 ref_hi) {
    lo = ref_lo < lo ? ref_lo : lo;
    hi = ref_hi > hi ? ref_hi : hi;
  }
  void grow(Row4 point) { grow(point, point); }
  void grow(const Box4& b) { grow(b.lo, b.hi); }
  Aabb aabb() const { return Aabb{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
  float surface_area() const { return aabb().surface_area(); }
};

void bounds_of(const PrimRef* first, const PrimRef* last, Aabb& box, Aabb& centroids) {
  Box4 b, c;
  for (const PrimRef* r = first; r != last; ++r) {
    Row4 lo, hi;
    rows_of(*r, lo, hi);
    b.grow(lo, hi);
    c.grow(centroid2_row(lo, hi));
  }
  box = b.aabb();
  centroids = c.aabb();
}

// The SAH's costs: a node visit against `block` primitives tested at a time in a leaf.
struct SahCosts {
  float traversal;
  uint32_t block;
  // Whole blocks: the integer division rounds up to the blocks a leaf of n fills.
  float tests(uint32_t n) const {
    return float((n + block - 1) / block);  // NOLINT(bugprone-integer-division)
  }
  float leaf(uint32_t n) const { return kIntersectCost * tests(n); }
};

std::vector<PrimRef> prim_refs(const std::vector<Aabb>& bounds) {
  std::vector<PrimRef> refs(bounds.size());
  for (uint32_t i = 0; i < uint32_t(bounds.size()); ++i)
    refs[i] = {bounds[i].lo, i, bounds[i].hi, 0};
  return refs;
}

// The binned SAH split of a node's primitives of least cost (axis -1 when no axis has extent or
// no split leaves both sides non-empty): centroids binned into kBins slots per axis, then a sweep
// of the bins from the right for the area and count right of every split and one from the left.
Split find_binned_split(const PrimRef* first, const PrimRef* last, const BuildTask& task,
                        const SahCosts& costs) {
  const Aabb& centroid_box = task.centroid_box;
  const glm::vec3 extent = centroid_box.hi - centroid_box.lo;
  Box4 bin_box[3][kBins];
  uint32_t bin_count[3][kBins] = {};
  Row4 scale = {0.0f, 0.0f, 0.0f, 0.0f};
  const Row4 origin = {centroid_box.lo[0], centroid_box.lo[1], centroid_box.lo[2], 0.0f};
  for (int a = 0; a < 3; ++a) scale[a] = extent[a] > 0.0f ? float(kBins) / extent[a] : 0.0f;
  // Every axis is binned, unrolled: one without extent has scale 0 and puts everything in bin 0,
  // and the sweep below skips it.
  for (const PrimRef* r = first; r != last; ++r) {
    Row4 lo, hi;
    rows_of(*r, lo, hi);
    // The bin on every axis at once: (c - origin) * scale truncated, as goes_left does per axis.
    const Int4 bins = __builtin_convertvector((centroid2_row(lo, hi) - origin) * scale, Int4);
    for (int a = 0; a < 3; ++a) {
      const int b = std::min(kBins - 1, int(bins[a]));
      RVR_DCHECK(b >= 0, "centroid below its node's centroid bounds: bin ", b);
      bin_count[a][b]++;
      bin_box[a][b].grow(lo, hi);
    }
  }
  Split best;
  float inv_area = 1.0f / std::max(task.box.surface_area(), 1e-30f);
  for (int a = 0; a < 3; ++a) {
    if (extent[a] <= 0.0f) continue;
    float right_area[kBins];
    uint32_t right_count[kBins];
    Box4 acc;
    uint32_t cnt = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.grow(bin_box[a][b]);
      cnt += bin_count[a][b];
      right_area[b] = acc.surface_area();
      right_count[b] = cnt;
    }
    acc = Box4();
    cnt = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      acc.grow(bin_box[a][b]);
      cnt += bin_count[a][b];
      if (cnt == 0 || right_count[b + 1] == 0) continue;
      float cost = costs.traversal + kIntersectCost * inv_area *
                                         (acc.surface_area() * costs.tests(cnt) +
                                          right_area[b + 1] * costs.tests(right_count[b + 1]));
      if (cost < best.cost) best = {a, b, cost};
    }
  }
  return best;
}

// A node's primitives split in two: [begin, mid) and [mid, end) of the PrimRef array, with each
// side's bounds and centroid bounds (the children's tasks).
struct Partition {
  uint32_t mid = 0;
  int axis = 0;
  Aabb left_box, left_centroids, right_box, right_centroids;
};

// Hoare partition at the split's bin that also gathers each side's bounds, so the children need
// no pass of their own.
Partition partition_at_bin(std::vector<PrimRef>& refs, const BuildTask& task, const Split& split) {
  Partition p;
  p.axis = split.axis;
  const glm::vec3 extent = task.centroid_box.hi - task.centroid_box.lo;
  const float scale = float(kBins) / extent[p.axis];
  const float lo = task.centroid_box.lo[p.axis];
  auto goes_left = [&](const PrimRef& r) {
    return std::min(kBins - 1, int((r.centroid2()[p.axis] - lo) * scale)) <= split.bin;
  };
  PrimRef* i = refs.data() + task.begin;
  PrimRef* j = refs.data() + task.end;
  Box4 left_box, left_centroids, right_box, right_centroids;
  auto add = [](const PrimRef& r, Box4& box, Box4& centroids) {
    Row4 lo, hi;
    rows_of(r, lo, hi);
    box.grow(lo, hi);
    centroids.grow(centroid2_row(lo, hi));
  };
  for (;;) {
    while (i < j && goes_left(*i)) add(*i++, left_box, left_centroids);
    while (i < j && !goes_left(*(j - 1))) add(*--j, right_box, right_centroids);
    if (i >= j) break;
    std::swap(*i, *(j - 1));
  }
  p.mid = uint32_t(i - refs.data());
  p.left_box = left_box.aabb();
  p.left_centroids = left_centroids.aabb();
  p.right_box = right_box.aabb();
  p.right_centroids = right_centroids.aabb();
  return p;
}

// No useful SAH split (all centroids equal, or too deep): the object median along the axis of
// widest centroid extent.
Partition partition_at_median(std::vector<PrimRef>& refs, const BuildTask& task) {
  Partition p;
  const glm::vec3 extent = task.centroid_box.hi - task.centroid_box.lo;
  p.axis = int(std::max_element(&extent[0], &extent[0] + 3) - &extent[0]);
  p.mid = task.begin + (task.end - task.begin) / 2;
  PrimRef* first = refs.data() + task.begin;
  PrimRef* mid = refs.data() + p.mid;
  PrimRef* last = refs.data() + task.end;
  std::nth_element(first, mid, last, [&](const PrimRef& a, const PrimRef& b) {
    return a.centroid2()[p.axis] < b.centroid2()[p.axis];
  });
  bounds_of(first, mid, p.left_box, p.left_centroids);
  bounds_of(mid, last, p.right_box, p.right_centroids);
  return p;
}

void set_leaf(BvhNode& node, const BuildTask& task) {
  const uint32_t count = task.end - task.begin;
  RVR_CHECK(count >= 1 && count <= std::numeric_limits<uint16_t>::max(),
            "a leaf's primitive count must fit BvhNode::count (uint16_t): ", count);
  node.lo = task.box.lo;
  node.hi = task.box.hi;
  node.offset = task.begin;
  node.count = uint16_t(count);
  node.axis = 0;
}

// An inner node; its `offset` (the second child) is set when that child is built.
void set_inner(BvhNode& node, const BuildTask& task, int axis) {
  node.lo = task.box.lo;
  node.hi = task.box.hi;
  node.count = 0;
  node.axis = uint8_t(axis);
}

}  // namespace

Bvh Bvh::build(const std::vector<Aabb>& bounds, const BvhBuildOptions& options) {
  const SahCosts costs{options.traversal_cost, uint32_t(std::max(1, options.leaf_block))};
  const uint32_t max_leaf = uint32_t(std::min(options.max_leaf_size, int(kMaxLeafSize)));
  auto start = std::chrono::steady_clock::now();
  Bvh bvh;
  RVR_CHECK(bounds.size() < size_t(~0u), "primitive indices are uint32_t and ~0u means none; ",
            bounds.size(), " primitives");
  const uint32_t n = uint32_t(bounds.size());
  bvh.stats_.primitives = n;
  if (n == 0) return bvh;

  std::vector<PrimRef> refs = prim_refs(bounds);
  bvh.nodes_.reserve(size_t(n) / 2 + 1);
  std::vector<BuildTask> tasks;
  {
    BuildTask root{0, n, ~0u, 0, {}, {}};
    bounds_of(refs.data(), refs.data() + n, root.box, root.centroid_box);
    tasks.push_back(root);
  }
  const float root_area = std::max(tasks[0].box.surface_area(), 1e-30f);
  size_t leaf_primitives = 0;
  // Depth first: each task's node is appended when it is taken, so a first child lands right
  // after its parent and a second child's index is written into the parent's `offset`.
  while (!tasks.empty()) {
    const BuildTask task = tasks.back();
    tasks.pop_back();
    const uint32_t index = uint32_t(bvh.nodes_.size());
    if (task.parent != ~0u) bvh.nodes_[task.parent].offset = index;
    bvh.nodes_.push_back({});
    bvh.stats_.max_depth = std::max(bvh.stats_.max_depth, task.depth);
    const uint32_t count = task.end - task.begin;
    const float area_ratio = task.box.surface_area() / root_area;

    const Split best =
        count > 1 && task.depth < kMedianDepth
            ? find_binned_split(refs.data() + task.begin, refs.data() + task.end, task, costs)
            : Split{};
    const bool must_split = count > max_leaf;
    if (count == 1 || (!must_split && !(best.cost < costs.leaf(count)))) {
      set_leaf(bvh.nodes_[index], task);
      bvh.stats_.leaves++;
      leaf_primitives += count;
      bvh.stats_.sah_cost += area_ratio * kIntersectCost * costs.tests(count);
      continue;
    }

    const Partition part =
        best.axis >= 0 ? partition_at_bin(refs, task, best) : partition_at_median(refs, task);
    RVR_CHECK(part.mid > task.begin && part.mid < task.end,
              "a split leaves both sides non-empty: [", task.begin, ", ", part.mid, ", ", task.end,
              ")");
    set_inner(bvh.nodes_[index], task, part.axis);
    bvh.stats_.sah_cost += area_ratio * costs.traversal;
    // Second child first onto the stack, so the first child is built next at index + 1.
    tasks.push_back(
        {part.mid, task.end, index, task.depth + 1, part.right_box, part.right_centroids});
    tasks.push_back(
        {task.begin, part.mid, ~0u, task.depth + 1, part.left_box, part.left_centroids});
  }
  RVR_CHECK(bvh.nodes_.size() == 2 * bvh.stats_.leaves - 1,
            "a binary tree has one inner node fewer than leaves: ", bvh.nodes_.size(), " nodes, ",
            bvh.stats_.leaves, " leaves");
  RVR_CHECK(bvh.stats_.max_depth < size_t(kStackSize),
            "object medians past kMedianDepth keep the depth within the traversal stack: depth ",
            bvh.stats_.max_depth);
  RVR_CHECK(leaf_primitives == n, "every primitive lies in exactly one leaf: ", leaf_primitives,
            " in leaves of ", n);
  bvh.order_.resize(n);
  for (uint32_t i = 0; i < n; ++i) bvh.order_[i] = refs[i].id;
  bvh.nodes_.shrink_to_fit();
  bvh.stats_.nodes = bvh.nodes_.size();
  bvh.stats_.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return bvh;
}

}  // namespace rvr
