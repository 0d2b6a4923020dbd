// The memory layout of the wide BVH, shared by its builder (wide_bvh.cpp, baseline x86-64) and
// its traversal kernels (src/kernels/, compiled once per instruction set). Plain data only:
// a kernel translation unit must not instantiate inline code that baseline code also uses,
// or the linker could hand an AVX2 copy of it to code running on any x86-64.
#pragma once

#include <cstdint>

namespace rvr {

constexpr int kWideBvhWidth = 8;   // children per node
constexpr int kTriangleBlock = 4;  // triangles per SoA leaf block
constexpr int kMaxLeafTriangles = 8;

// Eight child boxes in SoA, tested against a ray with one SIMD slab test (two halves with SSE).
// Rows are lower x, upper x, lower y, upper y, lower z, upper z, so the near and far planes of
// an axis are rows 2a + s and 2a + 1 - s, with s the sign bit of the ray's direction. An empty
// slot has lower = +inf, upper = -inf: no ray ever enters it.
struct alignas(32) WideNode {
  float bounds[6][kWideBvhWidth];
  uint32_t child[kWideBvhWidth];
};
static_assert(sizeof(WideNode) == 224, "wide nodes are 7 cache half-lines");

// Child references: an inner node's index, or a leaf of 1..8 triangles in consecutive blocks.
constexpr uint32_t kLeafFlag = 0x80000000u;
constexpr uint32_t kLeafCountBits = 4;
constexpr uint32_t kMaxBlocks = 1u << (31 - kLeafCountBits);
constexpr uint32_t kEmptyTree = 0xFFFFFFFFu;

// Four triangles as v0, e1 = v1 - v0, e2 = v2 - v0 in SoA, with the primitive index each lane
// reports. Unused lanes hold a degenerate triangle (e1 = e2 = 0: determinant 0, never hit) and
// primitive kUnusedLane.
struct alignas(16) TriangleBlock {
  float v0[3][kTriangleBlock];
  float e1[3][kTriangleBlock];
  float e2[3][kTriangleBlock];
  uint32_t primitive[kTriangleBlock];
};
static_assert(sizeof(TriangleBlock) == 160, "40 bytes per triangle when blocks are full");
constexpr uint32_t kUnusedLane = 0xFFFFFFFFu;

// What a kernel traverses.
struct WideBvhView {
  const WideNode* nodes = nullptr;
  const TriangleBlock* blocks = nullptr;
  uint32_t root = kEmptyTree;
  uint32_t max_depth = 0;  // levels of inner nodes below the root (bounds the stack)
};

// A ray for the kernels; t in (tmin, tmax).
struct KernelRay {
  float origin[3];
  float dir[3];
  float tmin;
  float tmax;
};

// Closest hit: t, barycentrics, primitive (kUnusedLane when nothing was hit).
struct KernelHit {
  float t;
  float u, v;
  uint32_t primitive;
};

struct KernelCounters {
  uint64_t nodes = 0;  // wide nodes whose children were tested
  uint64_t tests = 0;  // triangles tested (real lanes of the blocks visited)
};

// A tile of primary rays sharing one origin (a pinhole camera): up to kPacketRays directions in
// SoA, the same tmin and tmax for all.
constexpr int kPacketRays = 64;
// Primary rays go as packets of kPacketSide x kPacketSide pixel-centre rays.
constexpr int kPacketSide = 8;
static_assert(kPacketSide * kPacketSide == kPacketRays);
struct alignas(32) RayPacket {
  float origin[3];
  float tmin, tmax;
  int count;
  float dir[3][kPacketRays];
  // Bit k set for each ray k < count.
  uint64_t all() const { return count == kPacketRays ? ~uint64_t(0) : (uint64_t(1) << count) - 1; }
};

// Where the meshes' triangles lie in the triangle table a NamedTriangles indexes: object o's
// triangle p is entry first_triangle[o] + p, for p < triangle_count[o] (0 for an object that is
// not a mesh), o < objects.
struct TriangleNames {
  const uint32_t* first_triangle = nullptr;
  const uint32_t* triangle_count = nullptr;
  uint32_t objects = 0;
};

// Rays of one packet, each with the one triangle it is to be tested against (the hybrid's
// rebuild of a z-buffer's hits): ray k of the packet, for each bit k of `rays`, against triangle
// index[k] of `triangles` (9 floats each: v0, e1, e2). index[k] is read only for those rays.
struct NamedTriangles {
  const float* triangles;
  uint64_t rays = 0;
  uint32_t index[kPacketRays];
};
// What the test found for the rays of a NamedTriangles: the rays it hits (t, u, v in SoA, set
// for those rays), and those whose hit lies within intersect_triangle_mt's edge band, which the
// caller decides in double precision as that function does. Every other ray misses.
struct NamedHits {
  uint64_t hit = 0;
  uint64_t near_edge = 0;
  alignas(32) float t[kPacketRays];
  alignas(32) float u[kPacketRays];
  alignas(32) float v[kPacketRays];
};

// One instruction set's traversal functions. Counting variants fill KernelCounters (for the cost
// AOV and statistics); the others count nothing, for benchmarks.
struct TraversalKernels {
  const char* isa;
  bool (*closest)(const WideBvhView&, const KernelRay&, KernelHit&);
  bool (*closest_counted)(const WideBvhView&, const KernelRay&, KernelHit&, KernelCounters&);
  bool (*occluded)(const WideBvhView&, const KernelRay&);
  bool (*occluded_counted)(const WideBvhView&, const KernelRay&, KernelCounters&);
  // hits[i] for ray i of the packet, primitive kUnusedLane where it hits nothing; counters[i]
  // per ray, added to (may be null).
  void (*closest_packet)(const WideBvhView&, const RayPacket&, KernelHit* hits,
                         KernelCounters* counters);
  // The rays k of `rays` whose (object[k], primitive[k]) names a triangle of a mesh in `names`,
  // with that triangle's table entry in index[k] (left undefined for the others). object and
  // primitive hold kPacketRays entries; each group of eight with a ray in `rays` is read whole.
  uint64_t (*name_triangles)(const TriangleNames& names, const uint32_t* object,
                             const uint32_t* primitive, uint64_t rays, uint32_t* index);
  // intersect_triangle_mt's float pass for each ray of `named`, eight rays at a time, with the
  // packet's origin, tmin and tmax.
  void (*intersect_named)(const RayPacket& packet, const NamedTriangles& named, NamedHits& hits);
};

// Defined in baseline code (wide_bvh.cpp): the double-precision recheck of a hit near a
// triangle's edge, exactly as the scalar intersect_triangle_mt does it. tri = v0, e1, e2.
// Accepts t in (ray.tmin, t_limit] (t_limit included: ties are decided by primitive index).
bool recheck_triangle_near_edge(const KernelRay& ray, const float tri[9], float t_limit,
                                KernelHit& hit);

namespace isa_sse {
extern const TraversalKernels kKernels;
}
namespace isa_avx2 {
extern const TraversalKernels kKernels;
}
namespace isa_avx512 {
extern const TraversalKernels kKernels;
}

}  // namespace rvr
