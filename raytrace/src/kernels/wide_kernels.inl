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
// a * b - c, rounded twice as in the SSE kernels: a fused multiply-subtract (one instruction
// per slab) measured no faster here (A/B against Embree, min of 7 interleaved rounds: within
// the +-10% noise on every scene) and would let traversal counts, hence the cost AOV, differ
// between SSE and FMA kernels.
inline V8 mul_sub8(V8 a, V8 b, V8 c) { return {_mm256_sub_ps(_mm256_mul_ps(a.v, b.v), c.v)}; }
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
inline void store8u(float* p, V8 a) { _mm256_storeu_ps(p, a.v); }
inline V8 add8(V8 a, V8 b) { return {_mm256_add_ps(a.v, b.v)}; }
inline V8 div8(V8 a, V8 b) { return {_mm256_div_ps(a.v, b.v)}; }
inline V8 and8(V8 a, V8 b) { return {_mm256_and_ps(a.v, b.v)}; }
inline V8 or8(V8 a, V8 b) { return {_mm256_or_ps(a.v, b.v)}; }
inline V8 xor8(V8 a, V8 b) { return {_mm256_xor_ps(a.v, b.v)}; }
inline V8 andnot8(V8 a, V8 b) { return {_mm256_andnot_ps(a.v, b.v)}; }  // ~a & b
inline V8 lt8(V8 a, V8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)}; }
inline V8 le8(V8 a, V8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)}; }
inline V8 gt8(V8 a, V8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ)}; }
inline V8 eq8(V8 a, V8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_EQ_OQ)}; }
inline unsigned mask8(V8 m) { return unsigned(_mm256_movemask_ps(m.v)); }
inline V8 select8(V8 m, V8 b, V8 a) { return {_mm256_blendv_ps(a.v, b.v, m.v)}; }  // m ? b : a
// Lanes holding unsigned integers below 2^31 (primitive indices): a < b.
inline V8 lt_index8(V8 a, V8 b) {
  return {_mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_castps_si256(b.v), _mm256_castps_si256(a.v)))};
}
inline V8 bits8(uint32_t x) { return {_mm256_castsi256_ps(_mm256_set1_epi32(int(x)))}; }
// Lane i set when bit i of m is.
inline V8 lanes8(unsigned m) {
  const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  return {_mm256_castsi256_ps(
      _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(m)), bit), bit))};
}
#else
struct V8 {
  __m128 lo, hi;
};
inline V8 load8(const float* p) { return {_mm_load_ps(p), _mm_load_ps(p + 4)}; }
inline V8 splat8(float x) { return {_mm_set1_ps(x), _mm_set1_ps(x)}; }
inline V8 sub8(V8 a, V8 b) { return {_mm_sub_ps(a.lo, b.lo), _mm_sub_ps(a.hi, b.hi)}; }
inline V8 mul8(V8 a, V8 b) { return {_mm_mul_ps(a.lo, b.lo), _mm_mul_ps(a.hi, b.hi)}; }
// Two roundings; the margins of RayBox cover the second one.
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
inline void store8u(float* p, V8 a) {
  _mm_storeu_ps(p, a.lo);
  _mm_storeu_ps(p + 4, a.hi);
}
inline V8 add8(V8 a, V8 b) { return {_mm_add_ps(a.lo, b.lo), _mm_add_ps(a.hi, b.hi)}; }
inline V8 div8(V8 a, V8 b) { return {_mm_div_ps(a.lo, b.lo), _mm_div_ps(a.hi, b.hi)}; }
inline V8 and8(V8 a, V8 b) { return {_mm_and_ps(a.lo, b.lo), _mm_and_ps(a.hi, b.hi)}; }
inline V8 or8(V8 a, V8 b) { return {_mm_or_ps(a.lo, b.lo), _mm_or_ps(a.hi, b.hi)}; }
inline V8 xor8(V8 a, V8 b) { return {_mm_xor_ps(a.lo, b.lo), _mm_xor_ps(a.hi, b.hi)}; }
inline V8 andnot8(V8 a, V8 b) { return {_mm_andnot_ps(a.lo, b.lo), _mm_andnot_ps(a.hi, b.hi)}; }
inline V8 lt8(V8 a, V8 b) { return {_mm_cmplt_ps(a.lo, b.lo), _mm_cmplt_ps(a.hi, b.hi)}; }
inline V8 le8(V8 a, V8 b) { return {_mm_cmple_ps(a.lo, b.lo), _mm_cmple_ps(a.hi, b.hi)}; }
inline V8 gt8(V8 a, V8 b) { return {_mm_cmpgt_ps(a.lo, b.lo), _mm_cmpgt_ps(a.hi, b.hi)}; }
inline V8 eq8(V8 a, V8 b) { return {_mm_cmpeq_ps(a.lo, b.lo), _mm_cmpeq_ps(a.hi, b.hi)}; }
inline unsigned mask8(V8 m) {
  return unsigned(_mm_movemask_ps(m.lo)) | unsigned(_mm_movemask_ps(m.hi)) << 4;
}
inline __m128 select4(__m128 m, __m128 b, __m128 a) {
  return _mm_or_ps(_mm_and_ps(m, b), _mm_andnot_ps(m, a));  // SSE2 has no blendv
}
inline V8 select8(V8 m, V8 b, V8 a) { return {select4(m.lo, b.lo, a.lo), select4(m.hi, b.hi, a.hi)}; }
inline V8 lt_index8(V8 a, V8 b) {
  return {_mm_castsi128_ps(_mm_cmpgt_epi32(_mm_castps_si128(b.lo), _mm_castps_si128(a.lo))),
          _mm_castsi128_ps(_mm_cmpgt_epi32(_mm_castps_si128(b.hi), _mm_castps_si128(a.hi)))};
}
inline V8 bits8(uint32_t x) {
  __m128 v = _mm_castsi128_ps(_mm_set1_epi32(int(x)));
  return {v, v};
}
inline V8 lanes8(unsigned m) {
  const __m128i lo_bits = _mm_setr_epi32(1, 2, 4, 8), hi_bits = _mm_setr_epi32(16, 32, 64, 128);
  __m128i mm = _mm_set1_epi32(int(m));
  return {_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(mm, lo_bits), lo_bits)),
          _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(mm, hi_bits), hi_bits))};
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
// far planes per axis come from the direction's sign, and each slab is b * rdir - org * rdir
// with org * rdir precomputed. org * rdir is rounded once; the absolute margin moves the near planes
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

// One compare-exchange stage of a bitonic network over 8 lanes: every lane meets its partner
// (lane ^ J); `kMaxLanes` has a bit set for the lanes that keep the larger key. A lane takes its
// partner's key and payload only when the partner's key is strictly larger (smaller), so equal
// keys never duplicate a payload. Every kernel runs this same network (SSE on two halves), so
// children at equal distances come out in the same order and traversal counts agree too.
template <int J>
inline V8 partner8(V8 x) {
#if defined(__AVX2__)
  if (J == 1) return {_mm256_permute_ps(x.v, 0xB1)};
  if (J == 2) return {_mm256_permute_ps(x.v, 0x4E)};
  return {_mm256_permute2f128_ps(x.v, x.v, 1)};
#else
  if (J == 1) return {_mm_shuffle_ps(x.lo, x.lo, 0xB1), _mm_shuffle_ps(x.hi, x.hi, 0xB1)};
  if (J == 2) return {_mm_shuffle_ps(x.lo, x.lo, 0x4E), _mm_shuffle_ps(x.hi, x.hi, 0x4E)};
  return {x.hi, x.lo};
#endif
}

template <int J, unsigned kMaxLanes>
inline void exchange(V8& key, V8& payload) {
  V8 pk = partner8<J>(key), pp = partner8<J>(payload);
  V8 take = select8(lanes8(kMaxLanes), gt8(pk, key), lt8(pk, key));
  key = select8(take, pk, key);
  payload = select8(take, pp, payload);
}

// Three or more children hit: pushes all but the nearest, farthest first, and returns the
// nearest, with no branch that depends on the distances: a bitonic network sorts the eight
// (distance, child) pairs in registers (children not hit get -inf and sort last), and two
// full-width stores push them.
inline uint32_t visit_children(const WideNode& node, unsigned mask, V8 near, Stack& stack) {
  V8 key = select8(lanes8(mask), near, splat8(-__builtin_inff()));
  V8 payload = load8(reinterpret_cast<const float*>(node.child));
  // Descending bitonic sort: stages (k, j) = (2,1) (4,2) (4,1) (8,4) (8,2) (8,1); lane i keeps
  // the maximum when (i & k) == 0 equals i < (i ^ j).
  exchange<1, 0x99>(key, payload);
  exchange<2, 0xC3>(key, payload);
  exchange<1, 0xA5>(key, payload);
  exchange<4, 0x0F>(key, payload);
  exchange<2, 0x33>(key, payload);
  exchange<1, 0x55>(key, payload);
  store8u(reinterpret_cast<float*>(stack.ref + stack.top), payload);
  store8u(stack.dist + stack.top, key);
  stack.top += __builtin_popcount(mask) - 1;
  return stack.ref[stack.top];  // the nearest: stored, but not pushed
}


// From the subtree `start`, with what `closest` already holds (a packet's lane handed over to a
// single ray keeps its hit so far). For any-hit queries, true as soon as anything is hit.
template <bool kAnyHit, bool kCount, bool kRobust>
bool traverse_from(const WideBvhView& bvh, const KernelRay& ray, uint32_t start, Closest& closest,
                   KernelCounters* counters) {
  const RayBox box(ray);
  const BlockRay block_ray(ray);
  const V8 t_min = splat8(ray.tmin);
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

// ---------------------------------------------------------------------- packets of 8 rays

// Eight rays from one origin in the lanes of V8s. A node's children are tested one at a time
// against all eight (both planes per axis, then min/max, so each lane may point its own way);
// each lane keeps its own nearest hit, found with the same triangle arithmetic as a single ray,
// so every lane ends with exactly the hit a single ray would find.
struct Packet8 {
  V8 d[3];
  V8 rdir[3], org_rdir[3];
  V8 margin;  // per lane, absolute: covers the rounding of org * rdir (as RayBox's margins)
  V8 tmin;
  float o[3];
  unsigned valid;
  KernelRay ray[8];  // the same rays one by one: edge rechecks, single-ray fallback
};

struct PacketBest8 {
  V8 t, u, v, primitive;  // primitive: index bits; starts at 0 with t = tmax (see Closest)
  unsigned found;
};

// When this few lanes remain active at a node, each goes on alone (as Embree's hybrid
// traversal switches from packets to single rays): testing a node or a triangle costs a packet
// as much for one lane as for eight.
constexpr int kSingleRayThreshold = 2;

struct PacketStack {
  uint32_t ref[8 * 66];
  alignas(32) float near[8 * 66][8];
  int top = 0;
};

// Hands lane `lane` to the single-ray traversal of subtree `ref`, keeping its hit so far.
template <bool kCount>
void finish_lane(const WideBvhView& bvh, const Packet8& p, unsigned lane, uint32_t ref,
                 PacketBest8& best, KernelCounters* counters) {
  alignas(32) float t[8], u[8], v[8], prim[8];
  store8(t, best.t);
  store8(u, best.u);
  store8(v, best.v);
  store8(prim, best.primitive);
  Closest c;
  c.best.t = t[lane];
  c.best.u = u[lane];
  c.best.v = v[lane];
  __builtin_memcpy(&c.best.primitive, &prim[lane], 4);
  c.found = (best.found >> lane) & 1;
  traverse_from<false, kCount, false>(bvh, p.ray[lane], ref, c, kCount ? &counters[lane] : nullptr);
  if (!c.found) return;
  t[lane] = c.best.t;
  u[lane] = c.best.u;
  v[lane] = c.best.v;
  __builtin_memcpy(&prim[lane], &c.best.primitive, 4);
  best.t = load8(t);
  best.u = load8(u);
  best.v = load8(v);
  best.primitive = load8(prim);
  best.found |= 1u << lane;
}

// Lanes `active` against triangle `lane` of block b: intersect_triangle_mt lane by lane (s and
// q depend only on the shared origin, so they are computed once, in the same float operations).
inline void intersect_triangle8(const TriangleBlock& b, unsigned j, const Packet8& p,
                                unsigned active, PacketBest8& best) {
  const float e1x = b.e1[0][j], e1y = b.e1[1][j], e1z = b.e1[2][j];
  const float e2x = b.e2[0][j], e2y = b.e2[1][j], e2z = b.e2[2][j];
  const V8 E1x = splat8(e1x), E1y = splat8(e1y), E1z = splat8(e1z);
  const V8 E2x = splat8(e2x), E2y = splat8(e2y), E2z = splat8(e2z);
  // p = cross(d, e2), det = dot(e1, p)
  V8 px = sub8(mul8(p.d[1], E2z), mul8(E2y, p.d[2]));
  V8 py = sub8(mul8(p.d[2], E2x), mul8(E2z, p.d[0]));
  V8 pz = sub8(mul8(p.d[0], E2y), mul8(E2x, p.d[1]));
  V8 det = add8(add8(mul8(E1x, px), mul8(E1y, py)), mul8(E1z, pz));
  const float sx = p.o[0] - b.v0[0][j], sy = p.o[1] - b.v0[1][j], sz = p.o[2] - b.v0[2][j];
  const float qx = sy * e1z - e1y * sz, qy = sz * e1x - e1z * sx, qz = sx * e1y - e1x * sy;
  V8 su = add8(add8(mul8(splat8(sx), px), mul8(splat8(sy), py)), mul8(splat8(sz), pz));
  V8 sv = add8(add8(mul8(p.d[0], splat8(qx)), mul8(p.d[1], splat8(qy))), mul8(p.d[2], splat8(qz)));
  const V8 sign_bit = splat8(-0.0f);
  V8 sign = and8(det, sign_bit);
  V8 abs_det = andnot8(sign_bit, det);
  V8 U = xor8(su, sign), V = xor8(sv, sign), UV = add8(U, V);
  V8 outer_lo = mul8(splat8(-kEdgeBand), abs_det), outer_hi = mul8(splat8(1.0f + kEdgeBand), abs_det);
  V8 reject = or8(eq8(det, splat8(0.0f)), or8(or8(lt8(U, outer_lo), gt8(U, outer_hi)),
                                              or8(lt8(V, outer_lo), gt8(UV, outer_hi))));
  unsigned keep = active & ~mask8(reject);
  if (!keep) return;
  V8 band = mul8(splat8(kEdgeBand), abs_det), inner_hi = mul8(splat8(1.0f - kEdgeBand), abs_det);
  unsigned edge = keep & mask8(or8(or8(lt8(U, band), lt8(V, band)), gt8(UV, inner_hi)));
  unsigned inner = keep & ~edge;
  const V8 prim = bits8(b.primitive[j]);
  if (inner) {
    V8 inv = div8(splat8(1.0f), det);
    const float tnum = e2x * qx + e2y * qy + e2z * qz;  // dot(e2, q), as (x + y) + z
    V8 t = mul8(splat8(tnum), inv);
    V8 better = or8(lt8(t, best.t), and8(eq8(t, best.t), lt_index8(prim, best.primitive)));
    V8 take = and8(and8(lanes8(inner), gt8(t, p.tmin)), better);
    unsigned taken = mask8(take);
    if (taken) {
      best.t = select8(take, t, best.t);
      best.u = select8(take, mul8(su, inv), best.u);
      best.v = select8(take, mul8(sv, inv), best.v);
      best.primitive = select8(take, prim, best.primitive);
      best.found |= taken;
    }
  }
  if (edge) {
    float tri[9];
    lane_triangle(b, j, tri);
    alignas(32) float bt[8];
    store8(bt, best.t);
    for (; edge; edge &= edge - 1) {
      unsigned lane = lowest_bit(edge);
      KernelHit h;
      if (!recheck_triangle_near_edge(p.ray[lane], tri, bt[lane], h)) continue;
      alignas(32) float t[8], u[8], v[8], pr[8];
      store8(t, best.t);
      store8(u, best.u);
      store8(v, best.v);
      store8(pr, best.primitive);
      uint32_t cur;
      __builtin_memcpy(&cur, &pr[lane], 4);
      if (!(h.t < t[lane] || (h.t == t[lane] && b.primitive[j] < cur))) continue;
      t[lane] = h.t;
      u[lane] = h.u;
      v[lane] = h.v;
      __builtin_memcpy(&pr[lane], &b.primitive[j], 4);
      bt[lane] = h.t;
      best.t = load8(t);
      best.u = load8(u);
      best.v = load8(v);
      best.primitive = load8(pr);
      best.found |= 1u << lane;
    }
  }
}

template <bool kCount>
void traverse_packet(const WideBvhView& bvh, const Packet8& p, PacketBest8& best,
                     KernelCounters* counters) {
  PacketStack stack;
  stack.ref[0] = bvh.root;
  store8(stack.near[0], p.tmin);
  stack.top = 1;
  const V8 inf = splat8(__builtin_inff());
  // Work per lane, counted in float lanes (exact up to 2^24 per ray) with one add per step.
  V8 nodes = splat8(0.0f), tests = splat8(0.0f);
  while (stack.top > 0) {
    --stack.top;
    uint32_t ref = stack.ref[stack.top];
    unsigned active = p.valid & mask8(le8(load8(stack.near[stack.top]), best.t));
    if (!active) continue;
    if (__builtin_popcount(active) <= kSingleRayThreshold) {
      for (; active; active &= active - 1)
        finish_lane<kCount>(bvh, p, lowest_bit(active), ref, best, counters);
      continue;
    }
    if (!(ref & kLeafFlag)) {
      if (kCount) nodes = add8(nodes, and8(lanes8(active), splat8(1.0f)));
      const WideNode& node = bvh.nodes[ref];
      const V8 act = lanes8(active);
      uint32_t refs[kWideBvhWidth];
      float keys[kWideBvhWidth];
      alignas(32) float nears[kWideBvhWidth][8];
      int n = 0;
      for (int i = 0; i < kWideBvhWidth && node.child[i] != kEmptyTree; ++i) {
        V8 tn[3], tf[3];
        for (int a = 0; a < 3; ++a) {
          V8 t_lo = mul_sub8(splat8(node.bounds[2 * a][i]), p.rdir[a], p.org_rdir[a]);
          V8 t_hi = mul_sub8(splat8(node.bounds[2 * a + 1][i]), p.rdir[a], p.org_rdir[a]);
          tn[a] = min8(t_lo, t_hi);
          tf[a] = max8(t_lo, t_hi);
        }
        V8 t0 = sub8(max8(tn[2], max8(tn[1], max8(tn[0], p.tmin))), p.margin);
        V8 t1 = mul8(add8(min8(tf[2], min8(tf[1], min8(tf[0], best.t))), p.margin), splat8(kWiden));
        V8 hit = and8(act, le8(t0, t1));
        if (!mask8(hit)) continue;
        // The child's distance for ordering: its nearest entry among the lanes that hit it.
        V8 d = select8(hit, t0, inf);
        alignas(32) float dd[8];
        store8(dd, d);
        float key = dd[0];
        for (int k = 1; k < 8; ++k) key = dd[k] < key ? dd[k] : key;
        int k = n++;
        for (; k > 0 && keys[k - 1] < key; --k) {  // descending: the nearest ends last
          keys[k] = keys[k - 1];
          refs[k] = refs[k - 1];
          for (int l = 0; l < 8; ++l) nears[k][l] = nears[k - 1][l];
        }
        keys[k] = key;
        refs[k] = node.child[i];
        store8(nears[k], select8(hit, t0, inf));  // lanes that missed it never go in
      }
      for (int k = 0; k < n; ++k) {
        stack.ref[stack.top] = refs[k];
        for (int l = 0; l < 8; ++l) stack.near[stack.top][l] = nears[k][l];
        ++stack.top;
      }
      continue;
    }
    const uint32_t first = (ref & ~kLeafFlag) >> kLeafCountBits;
    const uint32_t triangles = ref & ((1u << kLeafCountBits) - 1);
    if (kCount) tests = add8(tests, and8(lanes8(active), splat8(float(triangles))));
    for (uint32_t k = 0; k < triangles; ++k)
      intersect_triangle8(bvh.blocks[first + k / kTriangleBlock], k % kTriangleBlock, p, active,
                          best);
  }
  if (kCount) {
    alignas(32) float n[8], t[8];
    store8(n, nodes);
    store8(t, tests);
    for (int l = 0; l < 8; ++l) {
      counters[l].nodes += uint64_t(n[l]);
      counters[l].tests += uint64_t(t[l]);
    }
  }
}

// Sets up lanes [first, first + 8) of a tile; false when a direction has a zero component (such
// rays take the robust single-ray path). Eight lanes at once: the reciprocal directions are one
// vector division per axis, each lane rounding as the scalar 1 / d does.
bool make_packet8(const RayPacket& packet, int first, Packet8& p) {
  const int live = packet.count - first < 8 ? packet.count - first : 8;
  p.valid = (1u << live) - 1u;
  alignas(32) float d[3][8];
  for (int a = 0; a < 3; ++a)  // unused lanes copy a live one
    for (int l = 0; l < 8; ++l) d[a][l] = packet.dir[a][l < live ? first + l : first];
  const V8 sign_off = bits8(0x7FFFFFFFu);
  V8 margin = splat8(0.0f);
  for (int a = 0; a < 3; ++a) {
    const V8 da = load8(d[a]);
    if (mask8(lt8(and8(sign_off, da), splat8(kTinyDirection))) != 0) return false;
    const V8 rdir = div8(splat8(1.0f), da);
    const V8 org_rdir = mul8(splat8(packet.origin[a]), rdir);
    // 2^-20: org * rdir's rounding, x16; the largest over the axes, as e > m ? e : m.
    margin = max8(mul8(and8(sign_off, org_rdir), splat8(1.0f / 1048576.0f)), margin);
    p.d[a] = da;
    p.rdir[a] = rdir;
    p.org_rdir[a] = org_rdir;
    p.o[a] = packet.origin[a];
  }
  p.margin = margin;
  p.tmin = splat8(packet.tmin);
  for (int l = 0; l < 8; ++l) {
    for (int a = 0; a < 3; ++a) {
      p.ray[l].origin[a] = packet.origin[a];
      p.ray[l].dir[a] = d[a][l];
    }
    p.ray[l].tmin = packet.tmin;
    p.ray[l].tmax = packet.tmax;
  }
  return true;
}

template <bool kCount>
void closest_packet_impl(const WideBvhView& bvh, const RayPacket& packet, KernelHit* hits,
                         KernelCounters* counters) {
  for (int first = 0; first < packet.count; first += 8) {
    Packet8 p;
    if (bvh.root == kEmptyTree) break;
    if (!make_packet8(packet, first, p)) {
      for (int i = first; i < first + 8 && i < packet.count; ++i) {
        KernelRay r{{packet.origin[0], packet.origin[1], packet.origin[2]},
                    {packet.dir[0][i], packet.dir[1][i], packet.dir[2][i]},
                    packet.tmin,
                    packet.tmax};
        trace<false, kCount>(bvh, r, &hits[i], kCount ? &counters[i] : nullptr);
      }
      continue;
    }
    PacketBest8 best{splat8(packet.tmax), splat8(0.0f), splat8(0.0f), bits8(0u), 0u};
    traverse_packet<kCount>(bvh, p, best, kCount ? counters + first : nullptr);
    alignas(32) float t[8], u[8], v[8], prim[8];
    store8(t, best.t);
    store8(u, best.u);
    store8(v, best.v);
    store8(prim, best.primitive);
    for (int l = 0; l < 8 && first + l < packet.count; ++l) {
      if (!((best.found >> l) & 1)) continue;
      KernelHit& h = hits[first + l];
      h.t = t[l];
      h.u = u[l];
      h.v = v[l];
      __builtin_memcpy(&h.primitive, &prim[l], 4);
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

// intersect_triangle_mt's float pass, lane by lane with its operations in its order (glm's
// cross and dot), eight rays each against its own triangle.
void intersect_named(const RayPacket& packet, const NamedTriangles& named, KernelHit* hits,
                     NamedOutcome* outcome) {
  const V8 zero = splat8(0.0f), sign_bit = bits8(0x80000000u);
  const V8 tmin = splat8(packet.tmin), tmax = splat8(packet.tmax);
  for (int first = 0; first < named.count; first += 8) {
    const V8 dx = load8(named.dir[0] + first), dy = load8(named.dir[1] + first),
             dz = load8(named.dir[2] + first);
    const V8 e1x = load8(named.e1[0] + first), e1y = load8(named.e1[1] + first),
             e1z = load8(named.e1[2] + first);
    const V8 e2x = load8(named.e2[0] + first), e2y = load8(named.e2[1] + first),
             e2z = load8(named.e2[2] + first);
    // p = cross(d, e2), det = dot(e1, p)
    const V8 px = sub8(mul8(dy, e2z), mul8(e2y, dz));
    const V8 py = sub8(mul8(dz, e2x), mul8(e2z, dx));
    const V8 pz = sub8(mul8(dx, e2y), mul8(e2x, dy));
    const V8 det = add8(add8(mul8(e1x, px), mul8(e1y, py)), mul8(e1z, pz));
    // sign = signbit(det) ? -1 : 1
    const V8 sign = or8(and8(sign_bit, det), splat8(1.0f));
    const V8 abs_det = mul8(det, sign);
    // s = origin - v0, su = dot(s, p), q = cross(s, e1), sv = dot(d, q)
    const V8 sx = sub8(splat8(packet.origin[0]), load8(named.v0[0] + first));
    const V8 sy = sub8(splat8(packet.origin[1]), load8(named.v0[1] + first));
    const V8 sz = sub8(splat8(packet.origin[2]), load8(named.v0[2] + first));
    const V8 su = add8(add8(mul8(sx, px), mul8(sy, py)), mul8(sz, pz));
    const V8 qx = sub8(mul8(sy, e1z), mul8(e1y, sz));
    const V8 qy = sub8(mul8(sz, e1x), mul8(e1z, sx));
    const V8 qz = sub8(mul8(sx, e1y), mul8(e1x, sy));
    const V8 sv = add8(add8(mul8(dx, qx), mul8(dy, qy)), mul8(dz, qz));
    const V8 U = mul8(su, sign), V = mul8(sv, sign), UV = add8(U, V);
    const V8 outer_lo = mul8(splat8(-kEdgeBand), abs_det);
    const V8 outer_hi = mul8(splat8(1.0f + kEdgeBand), abs_det);
    const V8 inner_lo = mul8(splat8(kEdgeBand), abs_det);
    const V8 inner_hi = mul8(splat8(1.0f - kEdgeBand), abs_det);
    const unsigned rejected = mask8(eq8(det, zero)) | mask8(lt8(U, outer_lo)) |
                              mask8(gt8(U, outer_hi)) | mask8(lt8(V, outer_lo)) |
                              mask8(gt8(UV, outer_hi));
    const unsigned near_edge = ~rejected & (mask8(lt8(U, inner_lo)) | mask8(lt8(V, inner_lo)) |
                                            mask8(gt8(UV, inner_hi)));
    const V8 inv_det = div8(splat8(1.0f), det);
    const V8 t = mul8(add8(add8(mul8(e2x, qx), mul8(e2y, qy)), mul8(e2z, qz)), inv_det);
    const unsigned in_range = mask8(gt8(t, tmin)) & mask8(lt8(t, tmax));
    const unsigned hit = ~rejected & ~near_edge & in_range;
    alignas(32) float ts[8], us[8], vs[8];
    store8(ts, t);
    store8(us, mul8(su, inv_det));
    store8(vs, mul8(sv, inv_det));
    for (int l = 0; l < 8 && first + l < named.count; ++l) {
      const unsigned bit = 1u << l;
      outcome[first + l] = (near_edge & bit) ? NamedOutcome::NearEdge
                           : (hit & bit)     ? NamedOutcome::Hit
                                             : NamedOutcome::Miss;
      if (hit & bit) hits[first + l] = {ts[l], us[l], vs[l], 0u};
    }
  }
}

}  // namespace

extern const TraversalKernels kKernels = {RVR_KERNEL_NAME,  closest,          closest_counted,
                                          occluded,         occluded_counted, closest_packet,
                                          intersect_named};

}  // namespace RVR_KERNEL_NS
}  // namespace rvr
