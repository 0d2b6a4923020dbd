// The scene as the tracer sees it: triangles precomputed as (v0, e1, e2), analytic spheres,
// squares and CSG solids, and what finds the nearest of them along a ray:
//  - bvh: the wide BVH over the triangles, traversed by SIMD kernels, plus a binary BVH over the
//    analytic shapes (a few in any scene);
//  - bvh2: one binary BVH over everything, one box at a time;
//  - none: the plain loop of the chapter; embree: Intel Embree.
// Among hits at the same t the lowest primitive index wins, so bvh, bvh2 and none return the
// same hit for every ray. Queries are two-phase: traversal finds the closest cheap hit (t,
// primitive, u, v); full surface data is computed once, for that hit only.
#pragma once

#include <stddef.h>

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/isa.h"
#include "rvr/core/ray.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/intersect.h"
#include "rvr/raytrace/wide_bvh.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

constexpr uint32_t kNoPrimitive = 0xFFFFFFFFu;

// Embree's device and scene when Embree answers the queries (embree_backend.cpp); opaque here so
// no Embree type leaks into this header.
struct EmbreeBackend;

struct EmbreeBackendDeleter {
  void operator()(EmbreeBackend* backend) const;
};

// The cheap hit kept during traversal.
struct HitRecord {
  float t = INFINITY;
  uint32_t primitive = kNoPrimitive;  // unified primitive index
  float u = 0.0f, v = 0.0f;           // triangle barycentrics
  uint32_t csg_leaf = 0;              // ShapeHit::part: which surface of the shape (CSG leaf)
  bool csg_flip = false;              // ShapeHit::flip: its normal reversed
};

// Everything shading needs, computed once for the closest hit.
struct SurfaceHit {
  float t = 0.0f;
  glm::vec3 position{0.0f};
  glm::vec3 geometric_normal{0.0f};  // unit; orientation as modelled (not flipped to viewer)
  glm::vec3 shading_normal{0.0f};    // unit; interpolated for smooth meshes
  uint32_t object = kNoId;
  uint32_t primitive = kNoId;  // triangle index in the object; 0 for analytic shapes
  uint32_t material = 0;
  float u = 0.0f, v = 0.0f;  // triangles: the hit's barycentrics (1 - u - v, u, v); else 0
};

// What surface() computes a triangle hit's surface from: the triangle's edges, its vertex
// normals (null where its mesh is flat), and its ids and material.
struct TriangleSurfaceData {
  const TrianglePrecomputed* triangle = nullptr;
  const glm::vec3* normal[3] = {nullptr, nullptr, nullptr};
  uint32_t object = kNoId;
  uint32_t primitive = kNoId;  // the id reported
  uint32_t material = 0;
};

// Embree's build quality: HIGH (spatial splits; what the embree renderer uses) or MEDIUM (binned
// SAH without spatial splits, the same kind of tree as ours).
enum class EmbreeQuality { High, Medium };

class TraceGeometry {
 public:
  // `isa` picks the SIMD kernels of the wide BVH; unset: selected_isa().
  TraceGeometry(const Scene& scene, SphereMode spheres, int sphere_segments, AccelKind accel,
                TriangleTest triangle_test = TriangleTest::MollerTrumbore,
                std::optional<Isa> isa = std::nullopt,
                EmbreeQuality embree_quality = EmbreeQuality::High);
  ~TraceGeometry();

  // Empty unless building failed (Embree could not make a device or scene, RVR_ISA asks for
  // kernels this CPU cannot run, the scene is too large for the wide BVH).
  const std::string& error() const { return error_.message; }
  ErrorKind error_kind() const { return error_.kind; }

  // Closest hit in (ray.tmin, ray.tmax).
  bool closest(const Ray& ray, HitRecord& hit, TraversalCounters& counters) const;
  // The same without counting traversal steps (benchmarks).
  bool closest(const Ray& ray, HitRecord& hit) const;
  // Closest hits of a tile of rays from one origin (primary rays), hits[i] for ray i: with the
  // wide BVH a packet traversal, otherwise one ray at a time. Same hits as closest().
  // counters[i], when not null, is set to ray i's traversal work (none with Embree). Every
  // hits[i] and counters[i] of the packet is written and none is read: they may be unset
  // (PacketSlots).
  void closest_packet(const RayPacket& packet, HitRecord* hits, TraversalCounters* counters) const;
  // Any hit in (ray.tmin, ray.tmax): shadow rays.
  bool occluded(const Ray& ray, TraversalCounters& counters) const;
  bool occluded(const Ray& ray) const;
  SurfaceHit surface(const Ray& ray, const HitRecord& hit) const;
  // The object and the primitive id reported (SurfaceHit's object and primitive) of a hit,
  // without the surface: what visibility needs.
  std::pair<uint32_t, uint32_t> hit_ids(const HitRecord& hit) const;
  // surface()'s inputs for triangle p (a unified index below triangle_count()), for the shading
  // kernels, which compute the same surface from them.
  TriangleSurfaceData triangle_surface_data(uint32_t p) const;
  // Asks the cache ahead for what triangle_surface_data (ids_only: hit_ids) reads of the
  // triangles hits[0, n) hit: its arrays' entries, then the mesh's vertex indices, then its
  // vertex normals (each level's addresses come from the one before). A block's misses overlap
  // instead of stalling one hit at a time; nothing is computed or changed.
  void fetch_surface_data(const HitRecord* hits, int n, bool ids_only) const;

  // The hit of `ray` with one thing a visibility buffer named, by the same intersection code as
  // closest(): for an object traced as triangles (a mesh, or a shape traced as its
  // tessellation, whose facets the z-buffers name alike) triangle `primitive` of it; for a shape
  // traced analytically the object. False when the ray misses it in (tmin, tmax) or the ids name
  // nothing.
  // counters.primitive_tests counts the tests made.
  bool intersect_named(const Ray& ray, uint32_t object, uint32_t primitive, HitRecord& hit,
                       TraversalCounters& counters) const;
  // Bounds of the shapes a z-buffer draws only approximately or not at all: analytic spheres
  // (their tessellation lies inside the exact silhouette) and CSG solids.
  std::vector<Aabb> approximated_bounds() const;
  // The scene objects those shapes are, ascending.
  std::vector<uint32_t> approximated_objects() const;
  // intersect_named for the rays of a packet at once: for each ray k of `wanted` (bit k), the
  // object[k] and primitive[k] a visibility buffer named; hits[k] as intersect_named gives it,
  // counters[k] its tests. Returns the rays that hit (bit k where intersect_named would return
  // true). With the wide BVH's kernels, the rays naming one triangle each are tested eight at a
  // time by the same operations (near an edge, by intersect_named itself).
  uint64_t intersect_named_packet(const RayPacket& packet, const uint32_t* object,
                                  const uint32_t* primitive, uint64_t wanted, HitRecord* hits,
                                  TraversalCounters* counters) const;
  // True when the scene holds CSG objects (which no z-buffer draws).
  bool has_csg() const { return !csg_primitives_.empty(); }
  // True when the scene holds shapes a z-buffer draws approximately or not at all (those of
  // approximated_bounds).
  bool has_approximated() const { return !approximated_primitives_.empty(); }
  // Closest hit among those shapes only, with closest()'s tie rule.
  bool closest_approximated(const Ray& ray, HitRecord& hit, TraversalCounters& counters) const;
  // closest_approximated for the rays of a packet in bit mask `rays` (ray k: bit k) at once, the
  // same hits: hits[k] is set where ray k meets one of those shapes (the bits returned) and left
  // as it was where it meets none; counters[k] counts its tests.
  uint64_t closest_approximated_packet(const RayPacket& packet, uint64_t rays, HitRecord* hits,
                                       TraversalCounters* counters) const;

  // The bounds of every primitive the tracer intersects (empty: none).
  const Aabb& bounds() const { return bounds_; }
  size_t primitive_count() const { return triangles_.size() + analytic_.size(); }
  size_t triangle_count() const { return triangles_.size(); }
  // Triangle p (a unified primitive index below triangle_count()).
  const TrianglePrecomputed& triangle(uint32_t p) const { return triangles_[p]; }
  // bvh2: the tree over every primitive; bvh: the tree over the analytic shapes only.
  const Bvh& bvh() const { return bvh_; }
  const WideBvh& wide_bvh() const { return wide_; }
  AccelKind accel() const { return accel_; }
  // The instruction set of the kernels the wide BVH runs ("sse", "avx2", "avx512").
  const char* kernel_isa() const { return kernels_ ? kernels_->isa : "scalar"; }
  // Embree's packet width (rtcIntersect8 or 16) when Embree answers; 0 otherwise.
  int embree_packet_width() const;
  // Bytes held for traversal: bvh: wide nodes + triangle blocks + the analytic shapes' tree;
  // bvh2: nodes + leaf-ordered triangles + slot indices; embree: what Embree's build of the
  // scene allocated and kept, as its memory monitor reports it.
  size_t acceleration_bytes() const;

 private:
  // An object the tracer traces analytically (rvr/core/shapes.h).
  struct Analytic {
    uint32_t object;
    TracedShape shape;
  };

  template <class TriangleTestFn, bool kAnyHit>
  bool query(const Ray& ray, HitRecord& hit, TraversalCounters& counters) const;
  // Closest hit among the analytic shapes `primitives` (unified indices), closest()'s tie rule.
  bool closest_among(const std::vector<uint32_t>& primitives, const Ray& ray, HitRecord& hit,
                     TraversalCounters& counters) const;
  template <bool kAnyHit>
  bool query_analytic(const Ray& ray, float t_max, HitRecord& hit,
                      TraversalCounters* counters) const;
  // intersect_named_packet's rays (bit k of `rays`: ray k) that name a shape traced analytically;
  // returns those that hit.
  uint64_t intersect_named_shapes(const RayPacket& packet, const uint32_t* object, uint64_t rays,
                                  HitRecord* hits, TraversalCounters* counters) const;
  void nearest_shape_hits(const RayPacket& packet, uint64_t rays, uint32_t analytic, float* t_max,
                          uint64_t& found, HitRecord* hits) const;
  // The analytic shapes' part of closest_packet: hits[k] holds ray k's triangle hit, if any.
  void closest_analytic_packet(const RayPacket& packet, HitRecord* hits,
                               TraversalCounters* counters) const;
  template <bool kCount>
  bool closest_wide(const Ray& ray, HitRecord& hit, TraversalCounters* counters) const;
  template <bool kCount>
  bool occluded_wide(const Ray& ray, TraversalCounters* counters) const;
  bool hit_analytic(const Analytic& a, const Ray& ray, float t_max, HitRecord& hit) const;
  static Aabb analytic_bounds(const Analytic& a);
  // Whether the shape's triangle form, which a z-buffer draws, is exactly it (a square).
  static bool triangle_form_exact(const Analytic& a);
  friend struct EmbreeBackend;
  friend bool embree_closest(const EmbreeBackend&, const Ray&, HitRecord&);
  friend void embree_closest_packet(const EmbreeBackend&, const RayPacket&, HitRecord*);

  AccelKind accel_;
  TriangleTest triangle_test_;
  EmbreeQuality embree_quality_;
  // Unified primitive index: [0, T) triangles, [T, T + A) analytic shapes.
  std::vector<TrianglePrecomputed> triangles_;
  std::vector<uint32_t> triangle_object_;
  std::vector<uint32_t> triangle_id_;       // primitive id reported: the index in its mesh
  std::vector<uint32_t> triangle_in_mesh_;  // index into the mesh's triangles (normals)
  std::vector<Analytic> analytic_;
  std::vector<const TriangleMesh*> object_mesh_;                   // per object, or null
  std::vector<std::unique_ptr<const TriangleMesh>> owned_meshes_;  // tessellated spheres
  std::vector<uint32_t> object_material_;
  std::vector<uint32_t> object_first_triangle_;  // unified index of each object's triangle 0
  std::vector<uint32_t> object_analytic_;        // index into analytic_, or kNoPrimitive
  std::vector<uint32_t> csg_primitives_;         // unified indices of the CSG objects
  Aabb bounds_;
  std::vector<uint32_t> approximated_primitives_;  // ... of approximated_bounds' shapes
  std::vector<uint32_t> object_triangle_count_;    // triangles in its mesh (0: none)
  // bvh2: leaf slots of bvh_ hold a primitive index and, for triangles, a copy in leaf order for
  // locality. bvh: bvh_ is over analytic_ only (slot -> analytic index), wide_ over triangles_.
  Bvh bvh_;
  TraversalVector<uint32_t> slot_primitive_;
  TraversalVector<TrianglePrecomputed> slot_triangles_;
  WideBvh wide_;
  const TraversalKernels* kernels_ = nullptr;
  std::unique_ptr<EmbreeBackend, EmbreeBackendDeleter> embree_;
  Error error_{"", ErrorKind::Internal};
};

}  // namespace rvr
