// Traversal of the wide BVH for one instruction set. Included once per kernel translation unit
// (kernels_sse.cpp, kernels_avx2.cpp, kernels_avx512.cpp), each compiled with its own -m flags
// and defining RVR_KERNEL_NS. Everything here has internal linkage but the kKernels table, so no
// wide-instruction copy of a function can be picked by the linker for baseline code; a test
// checks the objects' symbols (tests/check_kernel_symbols.sh).
//
// Results do not depend on the instruction set: the box tests are conservative (they may let a
// ray into a box it misses by a rounding, never the reverse), the triangle test is the scalar
// intersect_triangle_mt operation for operation (no FMA: these units build with
// -ffp-contract=off), and among hits at equal t the lowest primitive index wins whatever the
// order of traversal.
#include <cstdint>

#include "rvr/core/check.h"
#include "rvr/raytrace/wide_bvh_layout.h"

#ifndef RVR_KERNEL_NS
#error "define RVR_KERNEL_NS (isa_sse, isa_avx2 or isa_avx512) before including this file"
#endif

#include "rvr/core/simd/simd.h"
#include "rvr/core/simd/vec3v.h"

namespace rvr {
namespace RVR_KERNEL_NS {
namespace {

// Eight lanes in every ISA for a wide node's children (and the hybrid's named triangles): the
// SIMD layer's vfloat8, native in AVX2 and AVX-512 units and two halves in SSE ones; triangle
// blocks take vfloat4; ray packets take vfloat16 (PV, below).
using namespace simd;
using V8 = vfloat8;
using M8 = vboolf8;
using I8 = vint8;  // primitive indices and child references, as bits
using V4 = vfloat4;
using M4 = vboolf4;
using Vec3f = Vec3v<float>;  // one triangle's vectors, shared by a packet's lanes

// a * b - c, rounded twice in every kernel: a fused multiply-subtract would let traversal
// counts, hence the cost AOV, differ between SSE and FMA kernels. The margins of RayBox cover
// the second rounding.
inline V8 mul_sub(V8 a, V8 b, V8 c) {
  return a * b - c;
}
inline unsigned lowest_bit(unsigned m) {
  return unsigned(__builtin_ctz(m));
}

// ----------------------------------------------------------------------- ray against boxes

// Exit distances are widened by this factor (pbrt's 1 + 2 gamma(3), with room): rounding in the
// slab arithmetic can then only let a ray into a box, never keep it out.
constexpr float kWiden = 1.0f + 1.0f / 1048576.0f;
// A direction component below this is treated as zero: the ray takes the robust slab test.
constexpr float kTinyDirection = 1e-20f;

float abs1(float x) {
  return __builtin_fabsf(x);  // no branch
}
bool sign1(float x) {
  return __builtin_signbit(x) != 0;
}

// One ray's constants for the slab tests of every node it meets, set up once per ray. Near and
// far planes per axis come from the direction's sign, and each slab is b * rdir - org * rdir
// with org * rdir precomputed. org * rdir is rounded once; the absolute margin moves the near
// planes back and the far planes forward by more than that rounding, so the test stays
// conservative. A direction with a zero component (an axis-parallel ray) has infinite rdir there:
// such rays take the robust form (b - org) * rdir, where a ray lying in a slab's plane gives NaN
// and the NaN-ignoring max/min leave that slab out.
struct RayBox {
  V8 rdir[3];
  V8 near_offset[3], far_offset[3];  // fast form: org * rdir -+ margin
  V8 origin[3];                      // robust form
  int near_row[3], far_row[3];
  bool robust;

  explicit RayBox(const KernelRay& r) {
    robust = false;
    for (int a = 0; a < 3; ++a) robust |= abs1(r.dir[a]) < kTinyDirection;
    for (int a = 0; a < 3; ++a) {
      float rd = 1.0f / r.dir[a];  // +-inf for +-0
      float org_rdir = robust ? 0.0f : r.origin[a] * rd;
      float margin = abs1(org_rdir) * (1.0f / 2097152.0f);  // 2^-21 relative
      rdir[a] = V8::splat(rd);
      near_offset[a] = V8::splat(org_rdir + margin);
      far_offset[a] = V8::splat(org_rdir - margin);
      origin[a] = V8::splat(r.origin[a]);
      int s = sign1(r.dir[a]) ? 1 : 0;
      near_row[a] = 2 * a + s;
      far_row[a] = 2 * a + 1 - s;
    }
  }

  // Bit i set when child i is entered in [t_min, t_max]; near[i] its entry distance.
  template <bool kRobust>
  unsigned intersect(const WideNode& n, V8 t_min, V8 t_max, V8& near) const {
    V8 tn[3], tf[3];
    for (int a = 0; a < 3; ++a) {
      if (kRobust) {
        tn[a] = (V8::load(n.bounds[near_row[a]]) - origin[a]) * rdir[a];
        tf[a] = (V8::load(n.bounds[far_row[a]]) - origin[a]) * rdir[a];
      } else {
        tn[a] = mul_sub(V8::load(n.bounds[near_row[a]]), rdir[a], near_offset[a]);
        tf[a] = mul_sub(V8::load(n.bounds[far_row[a]]), rdir[a], far_offset[a]);
      }
    }
    // max / min return their second operand when either is NaN (MAXPS / MINPS): the
    // accumulator goes second so a NaN slab leaves it unchanged.
    V8 t0 = max(tn[2], max(tn[1], max(tn[0], t_min)));
    V8 t1 = min(tf[2], min(tf[1], min(tf[0], t_max)));
    near = t0;
    return le_bits(t0, t1 * V8::splat(kWiden));
  }
};

// ------------------------------------------------------------- ray against triangle blocks

// As intersect_triangle_mt: within this band of an edge the barycentrics are recomputed in double.
constexpr float kEdgeBand = 1e-3f;

struct BlockRay {
  Vec3vf4 o, d;
  V4 tmin;
  explicit BlockRay(const KernelRay& r)
      : o(Vec3vf4::splat(r.origin)), d(Vec3vf4::splat(r.dir)), tmin(V4::splat(r.tmin)) {}
};

// Moller-Trumbore for four triangles: the same operations, in the same order, as the scalar
// intersect_triangle_mt. Returns the lanes to look at: `edge` lanes need the double recheck,
// the others are hits with t in (tmin, t_limit] (t, u, v stored).
struct BlockCandidates {
  unsigned inner, edge;
  alignas(16) float t[4], u[4], v[4];
};

inline void intersect_block(const TriangleBlock& b, const BlockRay& r, V4 t_limit,
                            BlockCandidates& out) {
  const Vec3vf4 E1 = Vec3vf4::load(b.e1), E2 = Vec3vf4::load(b.e2);
  const Vec3vf4 P = cross(r.d, E2);
  V4 det = dot(E1, P);
  V4 sign = signbits(det);  // x * (+-1) is x with its sign bit flipped
  V4 abs_det = abs(det);
  const Vec3vf4 S = r.o - Vec3vf4::load(b.v0);
  V4 su = dot(S, P);
  const Vec3vf4 Q = cross(S, E1);
  V4 sv = dot(r.d, Q);
  V4 U = su ^ sign, V = sv ^ sign, UV = U + V;
  V4 outer_lo = V4::splat(-kEdgeBand) * abs_det;
  V4 outer_hi = V4::splat(1.0f + kEdgeBand) * abs_det;
  // Ordered comparisons: a NaN rejects nothing here, exactly as in the scalar test.
  M4 reject = (det == V4::zero()) |
              (((U < outer_lo) | (U > outer_hi)) | ((V < outer_lo) | (UV > outer_hi)));
  unsigned keep = movemask(reject) ^ 0xFu;
  out.inner = out.edge = 0;
  if (!keep) return;  // most blocks: no division, no t
  V4 band = V4::splat(kEdgeBand) * abs_det;
  V4 inner_hi = V4::splat(1.0f - kEdgeBand) * abs_det;
  M4 edge = ((U < band) | (V < band)) | (UV > inner_hi);
  unsigned edge_bits = movemask(edge);
  out.edge = keep & edge_bits;
  unsigned inner = keep & ~edge_bits;
  if (!inner) return;
  V4 inv = V4::splat(1.0f) / det;
  V4 t = dot(E2, Q) * inv;
  M4 in_range = (t > r.tmin) & (t <= t_limit);
  out.inner = inner & movemask(in_range);
  if (out.inner) {
    store(out.t, t);
    store(out.u, su * inv);
    store(out.v, sv * inv);
  }
}

inline void lane_triangle(const TriangleBlock& b, unsigned lane, float tri[9]) {
  for (int a = 0; a < 3; ++a) {
    tri[a] = b.v0[a][lane];
    tri[3 + a] = b.e1[a][lane];
    tri[6 + a] = b.e2[a][lane];
  }
}

// ----------------------------------------------------------------------- single-ray traversal

// Entries still to visit, with the entry distance of each: popped entries farther than the
// nearest hit so far are skipped without loading them. SoA, so eight children can be pushed with
// two stores. Each inner level pushes at most seven entries; the slack takes full-width stores.
constexpr int kStackSize = 7 * 64 + 8;
struct Stack {
  alignas(32) uint32_t ref[kStackSize + kWideBvhWidth];
  alignas(32) float dist[kStackSize + kWideBvhWidth];
  int top = 0;
};

// The closest hit so far; ties at equal t go to the lower primitive index. best.primitive
// starts at 0 with t = tmax, so a hit exactly at tmax (excluded) never wins.
struct Closest {
  KernelHit best;
  bool found = false;
  void offer(float t, float u, float v, uint32_t primitive) {
    if (t < best.t || (t == best.t && primitive < best.primitive)) {
      best = {t, u, v, primitive};
      found = true;
    }
  }
};

// One compare-exchange stage of a bitonic network over 8 lanes: every lane meets its partner
// (lane ^ J); `kMaxLanes` has a bit set for the lanes that keep the larger key. A lane takes its
// partner's key and payload only when the partner's key is strictly larger (smaller), so equal
// keys never duplicate a payload. Every kernel runs this same network (SSE on two halves), so
// children at equal distances come out in the same order and traversal counts agree too.
template <int J, unsigned kMaxLanes>
inline void exchange(V8& key, I8& payload) {
  V8 pk = swap_lanes<J>(key);
  I8 pp = swap_lanes<J>(payload);
  M8 take = select(M8::from_bits(kMaxLanes), pk > key, pk < key);
  key = select(take, pk, key);
  payload = select(take, pp, payload);
}

// Three or more children hit: pushes all but the nearest, farthest first, and returns the
// nearest, with no branch that depends on the distances: a bitonic network sorts the eight
// (distance, child) pairs in registers (children not hit get -inf and sort last), and two
// full-width stores push them.
inline uint32_t visit_children(const WideNode& node, unsigned mask, V8 near, Stack& stack) {
  V8 key = select(M8::from_bits(mask), near, V8::splat(-__builtin_inff()));
  I8 payload = I8::load(node.child);
  // Descending bitonic sort: stages (k, j) = (2,1) (4,2) (4,1) (8,4) (8,2) (8,1); lane i keeps
  // the maximum when (i & k) == 0 equals i < (i ^ j).
  exchange<1, 0x99>(key, payload);
  exchange<2, 0xC3>(key, payload);
  exchange<1, 0xA5>(key, payload);
  exchange<4, 0x0F>(key, payload);
  exchange<2, 0x33>(key, payload);
  exchange<1, 0x55>(key, payload);
  storeu(stack.ref + stack.top, payload);
  storeu(stack.dist + stack.top, key);
  stack.top += __builtin_popcount(mask) - 1;
  RVR_DCHECK(stack.top <= kStackSize, "the wide BVH is at most 64 inner levels deep; stack at ",
             stack.top);
  return stack.ref[stack.top];  // the nearest: stored, but not pushed
}

// From the subtree `start`, with what `closest` already holds (a packet's lane handed over to a
// single ray keeps its hit so far). For any-hit queries, true as soon as anything is hit.
template <bool kAnyHit, bool kCount, bool kRobust>
bool traverse_from(const WideBvhView& bvh, const KernelRay& ray, uint32_t start, Closest& closest,
                   KernelCounters* counters) {
  const RayBox box(ray);
  const BlockRay block_ray(ray);
  const V8 t_min = V8::splat(ray.tmin);
  // Occlusion accepts t in (tmin, tmax): the largest float below tmax is the limit.
  const float any_limit = kAnyHit ? __builtin_nextafterf(ray.tmax, -__builtin_inff()) : 0.0f;
  Stack stack;
  stack.ref[0] = start;
  stack.dist[0] = -__builtin_inff();
  stack.top = 1;
  while (stack.top > 0) {
    --stack.top;
    if (stack.dist[stack.top] > closest.best.t) continue;  // a nearer hit is known: skip it
    uint32_t ref = stack.ref[stack.top];
    bool leaf_reached = true;
    while (!(ref & kLeafFlag)) {
      const WideNode& node = bvh.nodes[ref];
      if (kCount) counters->nodes++;
      V8 near;
      unsigned mask = box.intersect<kRobust>(node, t_min, V8::splat(closest.best.t), near);
      if (mask == 0) {
        leaf_reached = false;
        break;
      }
      if ((mask & (mask - 1)) == 0) {
        ref = node.child[lowest_bit(mask)];
      } else {
        unsigned rest = mask & (mask - 1);
        if ((rest & (rest - 1)) == 0) {  // two: the nearer now, the other later (no branch)
          alignas(32) float nd[kWideBvhWidth];
          store(nd, near);
          unsigned a = lowest_bit(mask), b = lowest_bit(rest);
          unsigned swap = nd[b] < nd[a];
          unsigned nearer = swap ? b : a, farther = swap ? a : b;
          stack.ref[stack.top] = node.child[farther];
          stack.dist[stack.top++] = nd[farther];
          RVR_DCHECK(stack.top <= kStackSize, "stack at ", stack.top);
          ref = node.child[nearer];
        } else {
          ref = visit_children(node, mask, near, stack);
        }
      }
    }
    if (!leaf_reached) continue;
    const uint32_t first = (ref & ~kLeafFlag) >> kLeafCountBits;
    const uint32_t triangles = ref & ((1u << kLeafCountBits) - 1);
    RVR_DCHECK(triangles >= 1 && triangles <= uint32_t(kMaxLeafTriangles), "leaf of ", triangles);
    if (kCount) counters->tests += triangles;
    for (uint32_t k = 0; k < (triangles + kTriangleBlock - 1) / kTriangleBlock; ++k) {
      const TriangleBlock& b = bvh.blocks[first + k];
      BlockCandidates c;
      float limit = kAnyHit ? any_limit : closest.best.t;
      intersect_block(b, block_ray, V4::splat(limit), c);
      if (kAnyHit && c.inner) return true;
      for (unsigned m = c.inner; m; m &= m - 1) {
        unsigned lane = lowest_bit(m);
        closest.offer(c.t[lane], c.u[lane], c.v[lane], b.primitive[lane]);
      }
      for (unsigned m = c.edge; m; m &= m - 1) {
        unsigned lane = lowest_bit(m);
        float tri[9];
        lane_triangle(b, lane, tri);
        KernelHit h;
        float edge_limit = kAnyHit ? any_limit : closest.best.t;
        if (!recheck_triangle_near_edge(ray, tri, edge_limit, h)) continue;
        if (kAnyHit) return true;
        closest.offer(h.t, h.u, h.v, b.primitive[lane]);
      }
    }
  }
  return kAnyHit ? false : closest.found;
}

template <bool kAnyHit, bool kCount, bool kRobust>
bool traverse(const WideBvhView& bvh, const KernelRay& ray, KernelHit* hit,
              KernelCounters* counters) {
  Closest closest;
  closest.best = {ray.tmax, 0.0f, 0.0f, 0u};
  bool found = traverse_from<kAnyHit, kCount, kRobust>(bvh, ray, bvh.root, closest, counters);
  if (!kAnyHit && found) *hit = closest.best;
  return found;
}

template <bool kAnyHit, bool kCount>
bool trace(const WideBvhView& bvh, const KernelRay& ray, KernelHit* hit, KernelCounters* counters) {
  if (bvh.root == kEmptyTree) return false;
  for (int a = 0; a < 3; ++a)
    if (abs1(ray.dir[a]) < kTinyDirection)
      return traverse<kAnyHit, kCount, true>(bvh, ray, hit, counters);
  return traverse<kAnyHit, kCount, false>(bvh, ray, hit, counters);
}

bool closest(const WideBvhView& bvh, const KernelRay& ray, KernelHit& hit) {
  return trace<false, false>(bvh, ray, &hit, nullptr);
}
bool closest_counted(const WideBvhView& bvh, const KernelRay& ray, KernelHit& hit,
                     KernelCounters& counters) {
  return trace<false, true>(bvh, ray, &hit, &counters);
}
bool occluded(const WideBvhView& bvh, const KernelRay& ray) {
  return trace<true, false>(bvh, ray, nullptr, nullptr);
}
bool occluded_counted(const WideBvhView& bvh, const KernelRay& ray, KernelCounters& counters) {
  return trace<true, true>(bvh, ray, nullptr, &counters);
}

// --------------------------------------------------------------------- packets of 16 rays

// A packet is kPacketLanes = 16 rays from one origin in the lanes of PVs, in every ISA (native in
// AVX-512 units, two 8-lane halves in AVX2 and SSE ones): a ray's work counts (the cost AOV,
// bvh.nodes_visited) depend on the rays it went with, so the width is the same everywhere.
// Sixteen lanes are two rows of a tile's 8 x 8 rays, as with Embree's rtcIntersect16.
using PV = vfloat16;
using PM = vboolf16;
using PI = vint16;  // primitive indices
using Vec3vP = Vec3v<PV>;
constexpr int kPacketLanes = 16;
constexpr unsigned kAllLanes = (1u << kPacketLanes) - 1u;
static_assert(kPacketRays % kPacketLanes == 0, "a tile is whole packets");

inline PV mul_sub(PV a, PV b, PV c) {  // as mul_sub of V8s
  return a * b - c;
}

// A node's children are tested one at a time against all the lanes (both planes per axis, then
// min/max, so each lane may point its own way); each lane keeps its own nearest hit, found with the
// same triangle arithmetic as a single ray, so every lane ends with exactly the hit a single ray
// would find.
struct Packet {
  Vec3vP d;
  PV rdir[3], org_rdir[3];
  PV margin;  // per lane, absolute: covers the rounding of org * rdir (as RayBox's margins)
  PV tmin;
  float tmin1;  // tmin, the same in every lane
  Vec3f o;
  float tmax1;  // tmax, the same in every lane
  unsigned valid;
  alignas(64) float dir[3][kPacketLanes];  // d lane by lane, for ray()
  // The packet as one interval ray (Boulos et al. 2006), for culling a node's children that no
  // lane can enter (cull_children): when every lane's direction has the same sign on each axis,
  // each reciprocal lies in [rdir_lo, rdir_hi] and the near plane of a box on axis a is bounds
  // row near_row[a] for every lane; margin_hi is the largest lane margin.
  bool coherent = false;
  float rdir_lo[3], rdir_hi[3];
  int near_row[3], far_row[3];
  float margin_hi;

  // Lane `lane` as a single ray: edge rechecks, the single-ray fallback.
  KernelRay ray(unsigned lane) const {
    return {{o[0], o[1], o[2]}, {dir[0][lane], dir[1][lane], dir[2][lane]}, tmin1, tmax1};
  }
};

struct PacketBest {
  PV t, u, v;
  PI primitive;  // starts at 0 with t = tmax (see Closest)
  unsigned found;
};

// When this few lanes remain active at a node, each goes on alone (as Embree's hybrid
// traversal switches from packets to single rays): testing a node or a triangle costs a packet
// as much for one lane as for eight.
constexpr int kSingleRayThreshold = 2;

struct PacketStack {
  static constexpr int kEntries = 8 * 66;
  uint32_t ref[kEntries];
  alignas(64) float near[kEntries][kPacketLanes];
  int top = 0;
};

// Hands lane `lane` to the single-ray traversal of subtree `ref`, keeping its hit so far.
template <bool kCount>
void finish_lane(const WideBvhView& bvh, const Packet& p, unsigned lane, uint32_t ref,
                 PacketBest& best, KernelCounters* counters) {
  alignas(64) float t[kPacketLanes], u[kPacketLanes], v[kPacketLanes];
  alignas(64) uint32_t prim[kPacketLanes];
  store(t, best.t);
  store(u, best.u);
  store(v, best.v);
  store(prim, best.primitive);
  Closest c;
  c.best.t = t[lane];
  c.best.u = u[lane];
  c.best.v = v[lane];
  c.best.primitive = prim[lane];
  c.found = (best.found >> lane) & 1;
  traverse_from<false, kCount, false>(bvh, p.ray(lane), ref, c, kCount ? &counters[lane] : nullptr);
  if (!c.found) return;
  t[lane] = c.best.t;
  u[lane] = c.best.u;
  v[lane] = c.best.v;
  prim[lane] = c.best.primitive;
  best.t = PV::load(t);
  best.u = PV::load(u);
  best.v = PV::load(v);
  best.primitive = PI::load(prim);
  best.found |= 1u << lane;
}

// Lanes `active` against triangle `lane` of block b: intersect_triangle_mt lane by lane (s and
// q depend only on the shared origin, so they are computed once, in the same float operations).
inline void intersect_triangle_packet(const TriangleBlock& b, unsigned j, const Packet& p,
                                      unsigned active, PacketBest& best) {
  const Vec3f e1 = column(b.e1, int(j)), e2 = column(b.e2, int(j));
  const Vec3vP P = cross(p.d, Vec3vP::splat(e2));
  PV det = dot(Vec3vP::splat(e1), P);
  const Vec3f s = p.o - column(b.v0, int(j));
  const Vec3f q = cross(s, e1);
  PV su = dot(Vec3vP::splat(s), P);
  PV sv = dot(p.d, Vec3vP::splat(q));
  PV sign = signbits(det);
  PV abs_det = abs(det);
  PV U = su ^ sign, V = sv ^ sign, UV = U + V;
  PV outer_lo = PV::splat(-kEdgeBand) * abs_det, outer_hi = PV::splat(1.0f + kEdgeBand) * abs_det;
  PM reject = (det == PV::splat(0.0f)) |
              (((U < outer_lo) | (U > outer_hi)) | ((V < outer_lo) | (UV > outer_hi)));
  unsigned keep = active & ~movemask(reject);
  if (!keep) return;
  PV band = PV::splat(kEdgeBand) * abs_det, inner_hi = PV::splat(1.0f - kEdgeBand) * abs_det;
  unsigned edge = keep & movemask(((U < band) | (V < band)) | (UV > inner_hi));
  unsigned inner = keep & ~edge;
  const PI prim = PI::splat(int32_t(b.primitive[j]));
  if (inner) {
    PV inv = PV::splat(1.0f) / det;
    PV t = PV::splat(dot(e2, q)) * inv;
    // Primitive indices are below 2^31: the signed comparison orders them.
    PM better = (t < best.t) | ((t == best.t) & (prim < best.primitive));
    PM take = (PM::from_bits(inner) & (t > p.tmin)) & better;
    unsigned taken = movemask(take);
    if (taken) {
      best.t = select(take, t, best.t);
      best.u = select(take, su * inv, best.u);
      best.v = select(take, sv * inv, best.v);
      best.primitive = select(take, prim, best.primitive);
      best.found |= taken;
    }
  }
  if (edge) {
    float tri[9];
    lane_triangle(b, j, tri);
    alignas(64) float bt[kPacketLanes];
    store(bt, best.t);
    for (; edge; edge &= edge - 1) {
      unsigned lane = lowest_bit(edge);
      KernelHit h;
      if (!recheck_triangle_near_edge(p.ray(lane), tri, bt[lane], h)) continue;
      alignas(64) float t[kPacketLanes], u[kPacketLanes], v[kPacketLanes];
      alignas(64) uint32_t pr[kPacketLanes];
      store(t, best.t);
      store(u, best.u);
      store(v, best.v);
      store(pr, best.primitive);
      if (!(h.t < t[lane] || (h.t == t[lane] && b.primitive[j] < pr[lane]))) continue;
      t[lane] = h.t;
      u[lane] = h.u;
      v[lane] = h.v;
      pr[lane] = b.primitive[j];
      bt[lane] = h.t;
      best.t = PV::load(t);
      best.u = PV::load(u);
      best.v = PV::load(v);
      best.primitive = PI::load(pr);
      best.found |= 1u << lane;
    }
  }
}

// The largest lane of a (no lane is NaN).
inline float max_lane(PV a) {
  return reduce_max(a);
}

// The children of `node` (bit i: child slot i) that no lane of `active` can enter, found for all
// eight slots at once with the packet's interval ray. A lane enters a child when the per-lane
// test of traverse_packet passes: t0 - margin <= (t1 + margin) * kWiden, with t0 the largest
// entry over the axes (and tmin) and t1 the smallest exit (and the lane's best t). Over the
// packet, each axis's entry (b - o) / d is at least the smaller of (b - o) * rdir_lo and
// (b - o) * rdir_hi (it is linear in the reciprocal), each exit at most the larger, and every
// best t at most the largest: a child whose largest entry bound exceeds its smallest exit bound,
// after margins wider than every rounding of either test (2^-18 of the planes' and origin's
// magnitudes, against the per-lane test's few ulps), has no lane that enters it. Slots whose
// bounds are infinite (empty) give NaN and are never culled here.
inline unsigned cull_children(const WideNode& node, const Packet& p, unsigned active,
                              const PacketBest& best) {
  const V8 slack = V8::splat(1.0f / 262144.0f);
  V8 entry = V8::splat(p.tmin1);
  V8 exit =
      V8::splat(max_lane(select(PM::from_bits(active), best.t, PV::splat(-__builtin_inff()))));
  for (int a = 0; a < 3; ++a) {
    const V8 o = V8::splat(p.o[a]);
    const V8 lo = V8::splat(p.rdir_lo[a]), hi = V8::splat(p.rdir_hi[a]);
    const V8 r = max(abs(lo), abs(hi));
    const V8 bn = V8::load(node.bounds[p.near_row[a]]), bf = V8::load(node.bounds[p.far_row[a]]);
    const V8 dn = bn - o, df = bf - o;
    const V8 near_lo = min(dn * lo, dn * hi) - (abs(bn) + abs(o)) * r * slack;
    const V8 far_hi = max(df * lo, df * hi) + (abs(bf) + abs(o)) * r * slack;
    entry = max(near_lo, entry);
    exit = min(far_hi, exit);
  }
  const V8 margin = V8::splat(p.margin_hi);
  const V8 lane_hi = (exit + margin) * V8::splat(kWiden);
  const V8 bound = lane_hi + abs(lane_hi) * slack;
  return movemask(entry - margin > bound);
}

template <bool kCount>
void traverse_packet(const WideBvhView& bvh, const Packet& p, PacketBest& best,
                     KernelCounters* counters) {
  PacketStack stack;
  stack.ref[0] = bvh.root;
  store(stack.near[0], p.tmin);
  stack.top = 1;
  const PV inf = PV::splat(__builtin_inff());
  // Work per lane, counted in float lanes (exact up to 2^24 per ray) with one add per step.
  PV nodes = PV::splat(0.0f), tests = PV::splat(0.0f);
  while (stack.top > 0) {
    --stack.top;
    uint32_t ref = stack.ref[stack.top];
    unsigned active = p.valid & movemask(PV::load(stack.near[stack.top]) <= best.t);
    if (!active) continue;
    if (__builtin_popcount(active) <= kSingleRayThreshold) {
      for (; active; active &= active - 1)
        finish_lane<kCount>(bvh, p, lowest_bit(active), ref, best, counters);
      continue;
    }
    if (!(ref & kLeafFlag)) {
      if (kCount) nodes = nodes + masked(PM::from_bits(active), PV::splat(1.0f));
      const WideNode& node = bvh.nodes[ref];
      const PM act = PM::from_bits(active);
      const unsigned culled = p.coherent ? cull_children(node, p, active, best) : 0u;
      uint32_t refs[kWideBvhWidth];
      float keys[kWideBvhWidth];
      alignas(64) float nears[kWideBvhWidth][kPacketLanes];
      int n = 0;
      for (int i = 0; i < kWideBvhWidth && node.child[i] != kEmptyTree; ++i) {
        if ((culled >> i) & 1u) continue;
        PV tn[3], tf[3];
        for (int a = 0; a < 3; ++a) {
          PV t_lo = mul_sub(PV::splat(node.bounds[2 * a][i]), p.rdir[a], p.org_rdir[a]);
          PV t_hi = mul_sub(PV::splat(node.bounds[2 * a + 1][i]), p.rdir[a], p.org_rdir[a]);
          tn[a] = min(t_lo, t_hi);
          tf[a] = max(t_lo, t_hi);
        }
        PV t0 = max(tn[2], max(tn[1], max(tn[0], p.tmin))) - p.margin;
        PV t1 = (min(tf[2], min(tf[1], min(tf[0], best.t))) + p.margin) * PV::splat(kWiden);
        PM hit = act & (t0 <= t1);
        if (!movemask(hit)) continue;
        // The child's distance for ordering: its nearest entry among the lanes that hit it.
        PV d = select(hit, t0, inf);
        const float key = -max_lane(-d);
        int k = n++;
        for (; k > 0 && keys[k - 1] < key; --k) {  // descending: the nearest ends last
          keys[k] = keys[k - 1];
          refs[k] = refs[k - 1];
          for (int l = 0; l < kPacketLanes; ++l) nears[k][l] = nears[k - 1][l];
        }
        keys[k] = key;
        refs[k] = node.child[i];
        store(nears[k], select(hit, t0, inf));  // lanes that missed it never go in
      }
      for (int k = 0; k < n; ++k) {
        stack.ref[stack.top] = refs[k];
        for (int l = 0; l < kPacketLanes; ++l) stack.near[stack.top][l] = nears[k][l];
        ++stack.top;
      }
      RVR_DCHECK(stack.top <= PacketStack::kEntries,
                 "the wide BVH is at most 64 inner levels deep; stack at ", stack.top);
      continue;
    }
    const uint32_t first = (ref & ~kLeafFlag) >> kLeafCountBits;
    const uint32_t triangles = ref & ((1u << kLeafCountBits) - 1);
    if (kCount) tests = tests + masked(PM::from_bits(active), PV::splat(float(triangles)));
    for (uint32_t k = 0; k < triangles; ++k)
      intersect_triangle_packet(bvh.blocks[first + k / kTriangleBlock], k % kTriangleBlock, p,
                                active, best);
  }
  if (kCount) {
    alignas(64) float n[kPacketLanes], t[kPacketLanes];
    store(n, nodes);
    store(t, tests);
    for (int l = 0; l < kPacketLanes; ++l) {
      counters[l].nodes += uint64_t(n[l]);
      counters[l].tests += uint64_t(t[l]);
    }
  }
}

// Sets up lanes [first, first + kPacketLanes) of a tile; false when a direction has a zero
// component (such rays take the robust single-ray path). All lanes at once: the reciprocal
// directions are one vector division per axis, each lane rounding as the scalar 1 / d does.
bool make_packet(const RayPacket& packet, int first, Packet& p) {
  const int live = packet.count - first < kPacketLanes ? packet.count - first : kPacketLanes;
  p.valid = (1u << live) - 1u;
  if (live == kPacketLanes) {
    for (int a = 0; a < 3; ++a) store(p.dir[a], PV::loadu(packet.dir[a] + first));
  } else {
    for (int a = 0; a < 3; ++a)  // unused lanes copy a live one
      for (int l = 0; l < kPacketLanes; ++l)
        p.dir[a][l] = packet.dir[a][l < live ? first + l : first];
  }
  PV margin = PV::splat(0.0f);
  for (int a = 0; a < 3; ++a) {
    const PV da = PV::load(p.dir[a]);
    if (movemask(abs(da) < PV::splat(kTinyDirection)) != 0) return false;
    const PV rdir = PV::splat(1.0f) / da;
    const PV org_rdir = PV::splat(packet.origin[a]) * rdir;
    // 2^-20: org * rdir's rounding, x16; the largest over the axes, as e > m ? e : m.
    margin = max(abs(org_rdir) * PV::splat(1.0f / 1048576.0f), margin);
    p.d[a] = da;
    p.rdir[a] = rdir;
    p.org_rdir[a] = org_rdir;
    p.o[a] = packet.origin[a];
  }
  p.margin = margin;
  p.tmin = PV::splat(packet.tmin);
  p.tmin1 = packet.tmin;
  p.coherent = true;
  for (int a = 0; a < 3; ++a) {
    const unsigned negative = movemask(p.rdir[a] < PV::splat(0.0f));
    p.coherent = p.coherent && (negative == 0u || negative == kAllLanes);
    p.rdir_lo[a] = -max_lane(-p.rdir[a]);
    p.rdir_hi[a] = max_lane(p.rdir[a]);
    p.near_row[a] = 2 * a + (negative ? 1 : 0);
    p.far_row[a] = 2 * a + (negative ? 0 : 1);
  }
  p.margin_hi = max_lane(margin);
  p.tmax1 = packet.tmax;
  return true;
}

template <bool kCount>
void closest_packet_impl(const WideBvhView& bvh, const RayPacket& packet, KernelHit* hits,
                         KernelCounters* counters) {
  if (bvh.root == kEmptyTree) {
    for (int i = 0; i < packet.count; ++i) hits[i].primitive = kUnusedLane;
    return;
  }
  for (int first = 0; first < packet.count; first += kPacketLanes) {
    Packet p;
    if (!make_packet(packet, first, p)) {
      for (int i = first; i < first + kPacketLanes && i < packet.count; ++i) {
        KernelRay r{{packet.origin[0], packet.origin[1], packet.origin[2]},
                    {packet.dir[0][i], packet.dir[1][i], packet.dir[2][i]},
                    packet.tmin,
                    packet.tmax};
        hits[i].primitive = kUnusedLane;  // unless it hits
        trace<false, kCount>(bvh, r, &hits[i], kCount ? &counters[i] : nullptr);
      }
      continue;
    }
    PacketBest best{PV::splat(packet.tmax), PV::splat(0.0f), PV::splat(0.0f), PI::splat(0), 0u};
    traverse_packet<kCount>(bvh, p, best, kCount ? counters + first : nullptr);
    alignas(64) float t[kPacketLanes], u[kPacketLanes], v[kPacketLanes];
    alignas(64) uint32_t prim[kPacketLanes];
    store(t, best.t);
    store(u, best.u);
    store(v, best.v);
    store(prim, best.primitive);
    for (int l = 0; l < kPacketLanes && first + l < packet.count; ++l) {
      KernelHit& h = hits[first + l];
      if (!((best.found >> l) & 1)) {
        h.primitive = kUnusedLane;
        continue;
      }
      h.t = t[l];
      h.u = u[l];
      h.v = v[l];
      h.primitive = prim[l];
    }
  }
}

void closest_packet(const WideBvhView& bvh, const RayPacket& packet, KernelHit* hits,
                    KernelCounters* counters) {
  if (counters)
    closest_packet_impl<true>(bvh, packet, hits, counters);
  else
    closest_packet_impl<false>(bvh, packet, hits, nullptr);
}

uint64_t name_triangles(const TriangleNames& names, const uint32_t* object,
                        const uint32_t* primitive, uint64_t rays, uint32_t* index) {
  const I8 objects = I8::splat(int32_t(names.objects));
  uint64_t named = 0;
  for (int first = 0; first < kPacketRays; first += 8) {
    const unsigned lanes = unsigned(rays >> first) & 0xFFu;
    if (lanes == 0) continue;
    const I8 o = I8::loadu(object + first), p = I8::loadu(primitive + first);
    // The table lookups only in lanes that name a known object: others are not read.
    const M8 known = M8::from_bits(lanes) & less_unsigned(o, objects);
    const M8 mesh = known & less_unsigned(p, gather(names.triangle_count, o, known));
    storeu(index + first, gather(names.first_triangle, o, mesh) + p);
    named |= uint64_t(movemask(mesh)) << first;
  }
  return named;
}

// The triangles rays [first, first + 8) of `named` are tested against, for the lanes of `rays`
// (bit l: ray first + l, at least one), the others repeating the lowest's: one triangle's
// vectors splatted when every ray names it (a z-buffer's pixels mostly name what their
// neighbours name), else gathered lane by lane.
void named_triangles(const NamedTriangles& named, int first, unsigned rays, Vec3vf8& v0,
                     Vec3vf8& e1, Vec3vf8& e2) {
  const uint32_t* index = named.index + first;
  const uint32_t lowest = index[lowest_bit(rays)];
  bool one = true;
  for (unsigned m = rays & (rays - 1); m != 0; m &= m - 1) one &= index[lowest_bit(m)] == lowest;
  if (one) {
    const float* t = named.triangles + 9 * size_t(lowest);
    v0 = Vec3vf8::splat(t[0], t[1], t[2]);
    e1 = Vec3vf8::splat(t[3], t[4], t[5]);
    e2 = Vec3vf8::splat(t[6], t[7], t[8]);
    return;
  }
  alignas(32) float lanes[3][3][8];  // v0, e1, e2 by axis and lane
  for (int l = 0; l < 8; ++l) {
    const float* t = named.triangles + 9 * size_t((rays >> l) & 1u ? index[l] : lowest);
    for (int v = 0; v < 3; ++v)
      for (int a = 0; a < 3; ++a) lanes[v][a][l] = t[3 * v + a];
  }
  v0 = Vec3vf8::load(lanes[0]);
  e1 = Vec3vf8::load(lanes[1]);
  e2 = Vec3vf8::load(lanes[2]);
}

// intersect_triangle_mt's float pass, lane by lane with its operations in its order (glm's
// cross and dot), eight rays each against its own triangle.
void intersect_named(const RayPacket& packet, const NamedTriangles& named, NamedHits& out) {
  const V8 tmin = V8::splat(packet.tmin), tmax = V8::splat(packet.tmax);
  out.hit = 0;
  out.near_edge = 0;
  for (int first = 0; first < packet.count; first += 8) {
    const unsigned rays = unsigned(named.rays >> first) & 0xFFu;
    if (rays == 0) continue;
    const int live = packet.count - first < 8 ? packet.count - first : 8;
    Vec3vf8 D;
    if (live == 8) {  // the packet's rows lie 24 bytes into it: unaligned
      D = {V8::loadu(packet.dir[0] + first), V8::loadu(packet.dir[1] + first),
           V8::loadu(packet.dir[2] + first)};
    } else {  // the packet's lanes past its count are unset: a live one repeated
      alignas(32) float dir[3][8];
      for (int a = 0; a < 3; ++a)
        for (int l = 0; l < 8; ++l) dir[a][l] = packet.dir[a][first + (l < live ? l : 0)];
      D = Vec3vf8::load(dir);
    }
    Vec3vf8 V0, E1, E2;
    named_triangles(named, first, rays, V0, E1, E2);
    const Vec3vf8 P = cross(D, E2);
    const V8 det = dot(E1, P);
    // U, V: su, sv times sign(det)
    const Vec3vf8 S = Vec3vf8::splat(packet.origin) - V0;
    const V8 su = dot(S, P);
    const Vec3vf8 Q = cross(S, E1);
    const V8 sv = dot(D, Q);
    const V8 sign = signbits(det) | V8::splat(1.0f);
    const V8 abs_det = abs(det);
    const V8 U = su * sign, V = sv * sign, UV = U + V;
    const V8 outer_lo = V8::splat(-kEdgeBand) * abs_det;
    const V8 outer_hi = V8::splat(1.0f + kEdgeBand) * abs_det;
    const V8 inner_lo = V8::splat(kEdgeBand) * abs_det;
    const V8 inner_hi = V8::splat(1.0f - kEdgeBand) * abs_det;
    const unsigned rejected = movemask((det == V8::splat(0.0f)) | (U < outer_lo) | (U > outer_hi) |
                                       (V < outer_lo) | (UV > outer_hi));
    const unsigned near_edge =
        rays & ~rejected & movemask(((U < inner_lo) | (V < inner_lo)) | (UV > inner_hi));
    const V8 inv_det = V8::splat(1.0f) / det;
    const V8 t = dot(E2, Q) * inv_det;
    const unsigned hit = rays & ~rejected & ~near_edge & movemask((t > tmin) & (t < tmax));
    // Whole vectors into the 64 slots (first + 8 <= kPacketRays): read only where hit.
    store(out.t + first, t);
    store(out.u + first, su * inv_det);
    store(out.v + first, sv * inv_det);
    out.hit |= uint64_t(hit) << first;
    out.near_edge |= uint64_t(near_edge) << first;
  }
}

}  // namespace

extern const TraversalKernels kKernels = {RVR_KERNEL_NAME, closest,          closest_counted,
                                          occluded,        occluded_counted, closest_packet,
                                          name_triangles,  intersect_named};

}  // namespace RVR_KERNEL_NS
}  // namespace rvr
