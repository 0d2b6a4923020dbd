// Binned SAH builder (as in pbrt-v4 and Embree): at each node, bin primitive centroids into
// kBins slots per axis, sweep the bins for the split of least surface-area cost, and stop
// when a leaf is cheaper than any split. Nodes come out in depth-first order.
#include "rvr/raytrace/bvh.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include "rvr/shared/check.h"

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

void bounds_of(const PrimRef* first, const PrimRef* last, Aabb& box, Aabb& centroids) {
  box = Aabb();
  centroids = Aabb();
  for (const PrimRef* r = first; r != last; ++r) {
    box.grow(Aabb{r->lo, r->hi});
    centroids.grow(r->centroid2());
  }
}

}  // namespace

Bvh Bvh::build(const std::vector<Aabb>& bounds, const BvhBuildOptions& options) {
  const float kTraversalCost = options.traversal_cost;
  const uint32_t block = uint32_t(std::max(1, options.leaf_block));
  auto tests = [block](uint32_t n) { return float((n + block - 1) / block); };
  auto start = std::chrono::steady_clock::now();
  Bvh bvh;
  RVR_CHECK(bounds.size() < size_t(~0u), "primitive indices are uint32_t and ~0u means none; ",
            bounds.size(), " primitives");
  const uint32_t n = uint32_t(bounds.size());
  bvh.stats_.primitives = n;
  if (n == 0) return bvh;

  std::vector<PrimRef> refs(n);
  for (uint32_t i = 0; i < n; ++i) refs[i] = {bounds[i].lo, i, bounds[i].hi, 0};
  bvh.nodes_.reserve(size_t(n) / 2 + 1);

  std::vector<BuildTask> tasks;
  {
    BuildTask root{0, n, ~0u, 0, {}, {}};
    bounds_of(refs.data(), refs.data() + n, root.box, root.centroid_box);
    tasks.push_back(root);
  }
  const float root_area = std::max(tasks[0].box.surface_area(), 1e-30f);
  size_t leaf_primitives = 0;
  while (!tasks.empty()) {
    BuildTask task = tasks.back();
    tasks.pop_back();
    uint32_t index = uint32_t(bvh.nodes_.size());
    if (task.parent != ~0u) bvh.nodes_[task.parent].offset = index;
    bvh.nodes_.push_back({});

    const Aabb& box = task.box;
    const Aabb& centroid_box = task.centroid_box;
    uint32_t count = task.end - task.begin;
    bvh.stats_.max_depth = std::max(bvh.stats_.max_depth, task.depth);
    float area_ratio = box.surface_area() / root_area;

    auto make_leaf = [&]() {
      BvhNode& node = bvh.nodes_[index];
      node.lo = box.lo;
      node.hi = box.hi;
      node.offset = task.begin;
      RVR_CHECK(count >= 1 && count <= std::numeric_limits<uint16_t>::max(),
                "a leaf's primitive count must fit BvhNode::count (uint16_t): ", count);
      node.count = uint16_t(count);
      node.axis = 0;
      bvh.stats_.leaves++;
      leaf_primitives += count;
      bvh.stats_.sah_cost += area_ratio * kIntersectCost * tests(count);
    };

    float leaf_cost = kIntersectCost * tests(count);
    Split best;
    glm::vec3 extent = centroid_box.hi - centroid_box.lo;
    if (count > 1 && task.depth < kMedianDepth) {
      Aabb bin_box[3][kBins];
      uint32_t bin_count[3][kBins] = {};
      float scale[3];
      for (int a = 0; a < 3; ++a) scale[a] = extent[a] > 0.0f ? float(kBins) / extent[a] : 0.0f;
      for (const PrimRef* r = refs.data() + task.begin; r != refs.data() + task.end; ++r) {
        glm::vec3 c = r->centroid2();
        Aabb prim{r->lo, r->hi};
        for (int a = 0; a < 3; ++a) {
          if (extent[a] <= 0.0f) continue;
          int b = std::min(kBins - 1, int((c[a] - centroid_box.lo[a]) * scale[a]));
          RVR_DCHECK(b >= 0, "centroid below its node's centroid bounds: bin ", b);
          bin_count[a][b]++;
          bin_box[a][b].grow(prim);
        }
      }
      float inv_area = 1.0f / std::max(box.surface_area(), 1e-30f);
      for (int a = 0; a < 3; ++a) {
        if (extent[a] <= 0.0f) continue;
        // Sweep from the right to get the area and count right of every split.
        float right_area[kBins];
        uint32_t right_count[kBins];
        Aabb acc;
        uint32_t cnt = 0;
        for (int b = kBins - 1; b > 0; --b) {
          acc.grow(bin_box[a][b]);
          cnt += bin_count[a][b];
          right_area[b] = acc.surface_area();
          right_count[b] = cnt;
        }
        acc = Aabb();
        cnt = 0;
        for (int b = 0; b < kBins - 1; ++b) {
          acc.grow(bin_box[a][b]);
          cnt += bin_count[a][b];
          if (cnt == 0 || right_count[b + 1] == 0) continue;
          float cost = kTraversalCost + kIntersectCost * inv_area *
                                            (acc.surface_area() * tests(cnt) +
                                             right_area[b + 1] * tests(right_count[b + 1]));
          if (cost < best.cost) best = {a, b, cost};
        }
      }
    }

    bool must_split = count > uint32_t(std::min(options.max_leaf_size, int(kMaxLeafSize)));
    if (count == 1 || (!must_split && !(best.cost < leaf_cost))) {
      make_leaf();
      continue;
    }

    uint32_t mid;
    int axis;
    Aabb left_box, left_centroids, right_box, right_centroids;
    PrimRef* first = refs.data() + task.begin;
    PrimRef* last = refs.data() + task.end;
    if (best.axis >= 0) {
      axis = best.axis;
      float scale = float(kBins) / extent[axis];
      float lo = centroid_box.lo[axis];
      auto goes_left = [&](const PrimRef& r) {
        return std::min(kBins - 1, int((r.centroid2()[axis] - lo) * scale)) <= best.bin;
      };
      // Hoare partition that also gathers each side's bounds, so the children need no pass of
      // their own.
      PrimRef* i = first;
      PrimRef* j = last;
      for (;;) {
        while (i < j && goes_left(*i)) {
          left_box.grow(Aabb{i->lo, i->hi});
          left_centroids.grow(i->centroid2());
          ++i;
        }
        while (i < j && !goes_left(*(j - 1))) {
          --j;
          right_box.grow(Aabb{j->lo, j->hi});
          right_centroids.grow(j->centroid2());
        }
        if (i >= j) break;
        std::swap(*i, *(j - 1));
      }
      mid = uint32_t(i - refs.data());
      RVR_CHECK(mid > task.begin && mid < task.end, "a SAH split leaves both sides non-empty: [",
                task.begin, ", ", mid, ", ", task.end, ")");
    } else {
      // No useful SAH split (all centroids equal, or too deep): split at the object median.
      axis = int(std::max_element(&extent[0], &extent[0] + 3) - &extent[0]);
      mid = task.begin + count / 2;
      std::nth_element(first, refs.data() + mid, last, [&](const PrimRef& a, const PrimRef& b) {
        return a.centroid2()[axis] < b.centroid2()[axis];
      });
      bounds_of(first, refs.data() + mid, left_box, left_centroids);
      bounds_of(refs.data() + mid, last, right_box, right_centroids);
    }

    BvhNode& node = bvh.nodes_[index];
    node.lo = box.lo;
    node.hi = box.hi;
    node.count = 0;
    node.axis = uint8_t(axis);
    bvh.stats_.sah_cost += area_ratio * kTraversalCost;
    // Second child first onto the stack, so the first child is built next at index + 1.
    tasks.push_back({mid, task.end, index, task.depth + 1, right_box, right_centroids});
    tasks.push_back({task.begin, mid, ~0u, task.depth + 1, left_box, left_centroids});
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
