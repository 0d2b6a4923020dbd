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
#include <immintrin.h>

#include <cstdint>

#include "rvr/raytrace/wide_bvh_layout.h"

#ifndef RVR_KERNEL_NS
#error "define RVR_KERNEL_NS (isa_sse, isa_avx2 or isa_avx512) before including this file"
#endif

namespace rvr {
namespace RVR_KERNEL_NS {
namespace {

// ------------------------------------------------------------------ eight floats at a time

#if defined(__AVX2__)
struct V8 {
  __m256 v;
};
inline V8 load8(const float* p) { return {_mm256_load_ps(p)}; }
inline V8 splat8(float x) { return {_mm256_set1_ps(x)}; }
inline V8 sub8(V8 a, V8 b) { return {_mm256_sub_ps(a.v, b.v)}; }
inline V8 mul8(V8 a, V8 b) { return {_mm256_mul_ps(a.v, b.v)}; }
// a * b - c in one rounding: the slab test's one instruction per plane.
inline V8 mul_sub8(V8 a, V8 b, V8 c) { return {_mm256_fmsub_ps(a.v, b.v, c.v)}; }
// max/min return their second operand when either is NaN (MAXPS/MINPS): the accumulator goes
// second so a NaN slab leaves it unchanged.
inline V8 max8(V8 a, V8 b) { return {_mm256_max_ps(a.v, b.v)}; }
inline V8 min8(V8 a, V8 b) { return {_mm256_min_ps(a.v, b.v)}; }
inline unsigned le_mask8(V8 a, V8 b) {
#if defined(__AVX512VL__)
  return unsigned(_mm256_cmp_ps_mask(a.v, b.v, _CMP_LE_OQ));
#else
  return unsigned(_mm256_movemask_ps(_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)));
#endif
}
inline void store8(float* p, V8 a) { _mm256_store_ps(p, a.v); }
#else
struct V8 {
  __m128 lo, hi;
};
inline V8 load8(const float* p) { return {_mm_load_ps(p), _mm_load_ps(p + 4)}; }
inline V8 splat8(float x) { return {_mm_set1_ps(x), _mm_set1_ps(x)}; }
inline V8 sub8(V8 a, V8 b) { return {_mm_sub_ps(a.lo, b.lo), _mm_sub_ps(a.hi, b.hi)}; }
inline V8 mul8(V8 a, V8 b) { return {_mm_mul_ps(a.lo, b.lo), _mm_mul_ps(a.hi, b.hi)}; }
// Without FMA: two roundings; the margins of RayBox cover the second one.
inline V8 mul_sub8(V8 a, V8 b, V8 c) { return sub8(mul8(a, b), c); }
inline V8 max8(V8 a, V8 b) { return {_mm_max_ps(a.lo, b.lo), _mm_max_ps(a.hi, b.hi)}; }
inline V8 min8(V8 a, V8 b) { return {_mm_min_ps(a.lo, b.lo), _mm_min_ps(a.hi, b.hi)}; }
inline unsigned le_mask8(V8 a, V8 b) {
  return unsigned(_mm_movemask_ps(_mm_cmple_ps(a.lo, b.lo))) |
         unsigned(_mm_movemask_ps(_mm_cmple_ps(a.hi, b.hi))) << 4;
}
inline void store8(float* p, V8 a) {
  _mm_store_ps(p, a.lo);
  _mm_store_ps(p + 4, a.hi);
}
#endif

inline unsigned lowest_bit(unsigned m) { return unsigned(__builtin_ctz(m)); }

// ----------------------------------------------------------------------- ray against boxes

// Exit distances are widened by this factor (pbrt's 1 + 2 gamma(3), with room): rounding in the
// slab arithmetic can then only let a ray into a box, never keep it out.
constexpr float kWiden = 1.0f + 1.0f / 1048576.0f;
// A direction component below this is treated as zero: the ray takes the robust slab test.
constexpr float kTinyDirection = 1e-20f;

float abs1(float x) { return __builtin_fabsf(x); }  // no branch
bool sign1(float x) { return __builtin_signbit(x) != 0; }

// One ray's constants for the slab tests of every node it meets, set up once per ray. Near and
// far planes per axis come from the direction's sign, so each slab is one multiply-subtract
// b * rdir - org * rdir. org * rdir is rounded once; the absolute margin moves the near planes
// back and the far planes forward by more than that rounding, so the test stays conservative.
// A direction with a zero component (an axis-parallel ray) has infinite rdir there: such rays
// take the robust form (b - org) * rdir, where a ray lying in a slab's plane gives NaN and the
// NaN-ignoring max/min leave that slab out.
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
      rdir[a] = splat8(rd);
      near_offset[a] = splat8(org_rdir + margin);
      far_offset[a] = splat8(org_rdir - margin);
      origin[a] = splat8(r.origin[a]);
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
        tn[a] = mul8(sub8(load8(n.bounds[near_row[a]]), origin[a]), rdir[a]);
        tf[a] = mul8(sub8(load8(n.bounds[far_row[a]]), origin[a]), rdir[a]);
      } else {
        tn[a] = mul_sub8(load8(n.bounds[near_row[a]]), rdir[a], near_offset[a]);
        tf[a] = mul_sub8(load8(n.bounds[far_row[a]]), rdir[a], far_offset[a]);
      }
    }
    V8 t0 = max8(tn[2], max8(tn[1], max8(tn[0], t_min)));
    V8 t1 = min8(tf[2], min8(tf[1], min8(tf[0], t_max)));
    near = t0;
    return le_mask8(t0, mul8(t1, splat8(kWiden)));
  }
};

// ------------------------------------------------------------- ray against triangle blocks

// As intersect_triangle_mt: within this band of an edge the barycentrics are recomputed in double.
constexpr float kEdgeBand = 1e-3f;

struct BlockRay {
  __m128 o[3], d[3], tmin;
  explicit BlockRay(const KernelRay& r) {
    for (int a = 0; a < 3; ++a) {
      o[a] = _mm_set1_ps(r.origin[a]);
      d[a] = _mm_set1_ps(r.dir[a]);
    }
    tmin = _mm_set1_ps(r.tmin);
  }
};

// Moller-Trumbore for four triangles: the same operations, in the same order, as the scalar
// intersect_triangle_mt. Returns the lanes to look at: `edge` lanes need the double recheck,
// the others are hits with t in (tmin, t_limit] (t, u, v stored).
struct BlockCandidates {
  unsigned inner, edge;
  alignas(16) float t[4], u[4], v[4];
};

inline __m128 dot3(__m128 ax, __m128 ay, __m128 az, __m128 bx, __m128 by, __m128 bz) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, bx), _mm_mul_ps(ay, by)), _mm_mul_ps(az, bz));
}

inline void intersect_block(const TriangleBlock& b, const BlockRay& r, __m128 t_limit,
                            BlockCandidates& out) {
  const __m128 e1x = _mm_load_ps(b.e1[0]), e1y = _mm_load_ps(b.e1[1]), e1z = _mm_load_ps(b.e1[2]);
  const __m128 e2x = _mm_load_ps(b.e2[0]), e2y = _mm_load_ps(b.e2[1]), e2z = _mm_load_ps(b.e2[2]);
  // p = cross(d, e2)
  __m128 px = _mm_sub_ps(_mm_mul_ps(r.d[1], e2z), _mm_mul_ps(e2y, r.d[2]));
  __m128 py = _mm_sub_ps(_mm_mul_ps(r.d[2], e2x), _mm_mul_ps(e2z, r.d[0]));
  __m128 pz = _mm_sub_ps(_mm_mul_ps(r.d[0], e2y), _mm_mul_ps(e2x, r.d[1]));
  __m128 det = dot3(e1x, e1y, e1z, px, py, pz);
  const __m128 sign_bit = _mm_set1_ps(-0.0f);
  __m128 sign = _mm_and_ps(det, sign_bit);  // x * (+-1) is x with its sign bit flipped
  __m128 abs_det = _mm_andnot_ps(sign_bit, det);
  __m128 sx = _mm_sub_ps(r.o[0], _mm_load_ps(b.v0[0]));
  __m128 sy = _mm_sub_ps(r.o[1], _mm_load_ps(b.v0[1]));
  __m128 sz = _mm_sub_ps(r.o[2], _mm_load_ps(b.v0[2]));
  __m128 su = dot3(sx, sy, sz, px, py, pz);
  // q = cross(s, e1)
  __m128 qx = _mm_sub_ps(_mm_mul_ps(sy, e1z), _mm_mul_ps(e1y, sz));
  __m128 qy = _mm_sub_ps(_mm_mul_ps(sz, e1x), _mm_mul_ps(e1z, sx));
  __m128 qz = _mm_sub_ps(_mm_mul_ps(sx, e1y), _mm_mul_ps(e1x, sy));
  __m128 sv = dot3(r.d[0], r.d[1], r.d[2], qx, qy, qz);
  __m128 U = _mm_xor_ps(su, sign), V = _mm_xor_ps(sv, sign), UV = _mm_add_ps(U, V);
  __m128 outer_lo = _mm_mul_ps(_mm_set1_ps(-kEdgeBand), abs_det);
  __m128 outer_hi = _mm_mul_ps(_mm_set1_ps(1.0f + kEdgeBand), abs_det);
  // Ordered comparisons: a NaN rejects nothing here, exactly as in the scalar test.
  __m128 reject = _mm_or_ps(_mm_cmpeq_ps(det, _mm_setzero_ps()),
                            _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(U, outer_lo), _mm_cmpgt_ps(U, outer_hi)),
                                      _mm_or_ps(_mm_cmplt_ps(V, outer_lo), _mm_cmpgt_ps(UV, outer_hi))));
  unsigned keep = unsigned(_mm_movemask_ps(reject)) ^ 0xFu;
  out.inner = out.edge = 0;
  if (!keep) return;  // most blocks: no division, no t
  __m128 band = _mm_mul_ps(_mm_set1_ps(kEdgeBand), abs_det);
  __m128 inner_hi = _mm_mul_ps(_mm_set1_ps(1.0f - kEdgeBand), abs_det);
  __m128 edge = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(U, band), _mm_cmplt_ps(V, band)),
                          _mm_cmpgt_ps(UV, inner_hi));
  unsigned edge_bits = unsigned(_mm_movemask_ps(edge));
  out.edge = keep & edge_bits;
  unsigned inner = keep & ~edge_bits;
  if (!inner) return;
  __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), det);
  __m128 t = _mm_mul_ps(dot3(e2x, e2y, e2z, qx, qy, qz), inv);
  __m128 in_range = _mm_and_ps(_mm_cmpgt_ps(t, r.tmin), _mm_cmple_ps(t, t_limit));
  out.inner = inner & unsigned(_mm_movemask_ps(in_range));
  if (out.inner) {
    _mm_store_ps(out.t, t);
    _mm_store_ps(out.u, _mm_mul_ps(su, inv));
    _mm_store_ps(out.v, _mm_mul_ps(sv, inv));
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

#if defined(__AVX2__)
// One compare-exchange stage of a bitonic network over 8 lanes: every lane meets its partner
// (lane ^ J); `kMaxLanes` has a bit set for the lanes that keep the larger key. A lane takes its
// partner's key and payload only when the partner's key is strictly larger (smaller), so equal
// keys never duplicate a payload.
template <int J, int kMaxLanes>
inline void exchange(__m256& key, __m256& payload) {
  __m256 pk, pp;
  if (J == 1) {
    pk = _mm256_permute_ps(key, 0xB1);
    pp = _mm256_permute_ps(payload, 0xB1);
  } else if (J == 2) {
    pk = _mm256_permute_ps(key, 0x4E);
    pp = _mm256_permute_ps(payload, 0x4E);
  } else {
    pk = _mm256_permute2f128_ps(key, key, 1);
    pp = _mm256_permute2f128_ps(payload, payload, 1);
  }
  __m256 take = _mm256_blend_ps(_mm256_cmp_ps(pk, key, _CMP_LT_OQ),
                                _mm256_cmp_ps(pk, key, _CMP_GT_OQ), kMaxLanes);
  key = _mm256_blendv_ps(key, pk, take);
  payload = _mm256_blendv_ps(payload, pp, take);
}

// Three or more children hit: pushes all but the nearest, farthest first, and returns the
// nearest, with no branch that depends on the distances: a bitonic network sorts the eight
// (distance, child) pairs in registers (children not hit get -inf and sort last), and two
// full-width stores push them.
inline uint32_t visit_children(const WideNode& node, unsigned mask, V8 near, Stack& stack) {
  const __m256i lanes = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  __m256 hit = _mm256_castsi256_ps(
      _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(mask)), lanes), lanes));
  __m256 key = _mm256_blendv_ps(_mm256_set1_ps(-__builtin_inff()), near.v, hit);
  __m256 payload = _mm256_castsi256_ps(_mm256_load_si256(reinterpret_cast<const __m256i*>(node.child)));
  // Descending bitonic sort: stages (k, j) = (2,1) (4,2) (4,1) (8,4) (8,2) (8,1); lane i keeps
  // the maximum when (i & k) == 0 equals i < (i ^ j).
  exchange<1, 0x99>(key, payload);
  exchange<2, 0xC3>(key, payload);
  exchange<1, 0xA5>(key, payload);
  exchange<4, 0x0F>(key, payload);
  exchange<2, 0x33>(key, payload);
  exchange<1, 0x55>(key, payload);
  const int hits = __builtin_popcount(mask);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack.ref + stack.top), _mm256_castps_si256(payload));
  _mm256_storeu_ps(stack.dist + stack.top, key);
  stack.top += hits - 1;
  return stack.ref[stack.top];  // the nearest: stored, but not pushed
}
#else
// Three or more children hit: sorted by insertion, farthest pushed first.
inline uint32_t visit_children(const WideNode& node, unsigned mask, V8 near8, Stack& stack) {
  alignas(32) float near[kWideBvhWidth];
  store8(near, near8);
  uint32_t refs[kWideBvhWidth];
  float dists[kWideBvhWidth];
  int n = 0;
  for (; mask; mask &= mask - 1) {
    unsigned i = lowest_bit(mask);
    int k = n++;
    for (; k > 0 && dists[k - 1] < near[i]; --k) {
      dists[k] = dists[k - 1];
      refs[k] = refs[k - 1];
    }
    dists[k] = near[i];
    refs[k] = node.child[i];
  }
  for (int k = 0; k < n - 1; ++k) {
    stack.ref[stack.top] = refs[k];
    stack.dist[stack.top++] = dists[k];
  }
  return refs[n - 1];
}
#endif


template <bool kAnyHit, bool kCount, bool kRobust>
bool traverse(const WideBvhView& bvh, const KernelRay& ray, KernelHit* hit,
              KernelCounters* counters) {
  const RayBox box(ray);
  const BlockRay block_ray(ray);
  const V8 t_min = splat8(ray.tmin);
  Closest closest;
  closest.best = {ray.tmax, 0.0f, 0.0f, 0u};
  // Occlusion accepts t in (tmin, tmax): the largest float below tmax is the limit.
  const float any_limit = kAnyHit ? __builtin_nextafterf(ray.tmax, -__builtin_inff()) : 0.0f;
  Stack stack;
  stack.ref[0] = bvh.root;
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
      unsigned mask = box.intersect<kRobust>(node, t_min, splat8(closest.best.t), near);
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
          store8(nd, near);
          unsigned a = lowest_bit(mask), b = lowest_bit(rest);
          unsigned swap = nd[b] < nd[a];
          unsigned nearer = swap ? b : a, farther = swap ? a : b;
          stack.ref[stack.top] = node.child[farther];
          stack.dist[stack.top++] = nd[farther];
          ref = node.child[nearer];
        } else {
          ref = visit_children(node, mask, near, stack);
        }
      }
    }
    if (!leaf_reached) continue;
    const uint32_t first = (ref & ~kLeafFlag) >> kLeafCountBits;
    const uint32_t triangles = ref & ((1u << kLeafCountBits) - 1);
    if (kCount) counters->tests += triangles;
    for (uint32_t k = 0; k < (triangles + kTriangleBlock - 1) / kTriangleBlock; ++k) {
      const TriangleBlock& b = bvh.blocks[first + k];
      BlockCandidates c;
      float limit = kAnyHit ? any_limit : closest.best.t;
      intersect_block(b, block_ray, _mm_set1_ps(limit), c);
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
  if (kAnyHit) return false;
  if (closest.found) *hit = closest.best;
  return closest.found;
}

template <bool kAnyHit, bool kCount>
bool trace(const WideBvhView& bvh, const KernelRay& ray, KernelHit* hit, KernelCounters* counters) {
  if (bvh.root == kEmptyTree) return false;
  for (int a = 0; a < 3; ++a)
    if (abs1(ray.dir[a]) < kTinyDirection) return traverse<kAnyHit, kCount, true>(bvh, ray, hit, counters);
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

// Placeholder until the packet traversal lands: single rays.
void closest_packet(const WideBvhView& bvh, const RayPacket& packet, KernelHit* hits,
                    KernelCounters* counters) {
  for (int i = 0; i < packet.count; ++i) {
    KernelRay r{{packet.origin[0], packet.origin[1], packet.origin[2]},
                {packet.dir[0][i], packet.dir[1][i], packet.dir[2][i]},
                packet.tmin,
                packet.tmax};
    hits[i].primitive = kUnusedLane;
    if (counters)
      closest_counted(bvh, r, hits[i], counters[i]);
    else
      closest(bvh, r, hits[i]);
  }
}

}  // namespace

extern const TraversalKernels kKernels = {RVR_KERNEL_NAME,  closest,          closest_counted,
                                          occluded,         occluded_counted, closest_packet};

}  // namespace RVR_KERNEL_NS
}  // namespace rvr
