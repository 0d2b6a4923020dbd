// The scene as the tracer sees it: triangles precomputed as (v0, e1, e2), analytic spheres,
// squares and CSG solids, one BVH over all of them (or none: the plain loop of the chapter).
// Queries are two-phase: traversal finds the closest cheap hit (t, primitive, u, v); full
// surface data is computed once, for that hit only.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/intersect.h"
#include "rvr/shared/renderer.h"
#include "rvr/shared/scene.h"

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
  uint32_t csg_leaf = 0;              // CSG: which leaf sphere's surface was hit
  bool csg_flip = false;              // CSG: surface of a subtracted solid (normal reversed)
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
};

class TraceGeometry {
 public:
  TraceGeometry(const Scene& scene, SphereMode spheres, int sphere_segments, AccelKind accel,
                TriangleTest triangle_test = TriangleTest::MollerTrumbore);
  ~TraceGeometry();

  // Empty unless building failed (Embree could not make a device or scene).
  const std::string& error() const { return error_; }

  // Closest hit in (ray.tmin, ray.tmax).
  bool closest(const Ray& ray, HitRecord& hit, TraversalCounters& counters) const;
  // Any hit in (ray.tmin, ray.tmax): shadow rays.
  bool occluded(const Ray& ray, TraversalCounters& counters) const;
  SurfaceHit surface(const Ray& ray, const HitRecord& hit) const;

  size_t primitive_count() const { return triangles_.size() + analytic_.size(); }
  size_t triangle_count() const { return triangles_.size(); }
  const Bvh& bvh() const { return bvh_; }
  AccelKind accel() const { return accel_; }
  // Bytes held for traversal: nodes + leaf-ordered triangles + slot indices.
  size_t acceleration_bytes() const;

 private:
  enum class Kind : uint8_t { Sphere, Square, Csg };
  struct Analytic {
    Kind kind;
    uint32_t object;
    Sphere sphere;
    Plane plane;
    glm::vec3 axis_u{0.0f}, axis_v{0.0f};
    const CsgNode* csg = nullptr;
    std::vector<Sphere> csg_leaves;  // depth-first, as HitRecord::csg_leaf numbers them
  };

  template <class TriangleTestFn, bool kAnyHit>
  bool query(const Ray& ray, HitRecord& hit, TraversalCounters& counters) const;
  bool hit_analytic(const Analytic& a, const Ray& ray, float t_max, HitRecord& hit) const;
  static Aabb analytic_bounds(const Analytic& a);
  friend struct EmbreeBackend;
  friend bool embree_closest(const EmbreeBackend&, const Ray&, HitRecord&);

  AccelKind accel_;
  TriangleTest triangle_test_;
  // Unified primitive index: [0, T) triangles, [T, T + A) analytic shapes.
  std::vector<TrianglePrecomputed> triangles_;
  std::vector<uint32_t> triangle_object_;
  std::vector<uint32_t> triangle_id_;       // primitive id reported (0 for tessellated spheres)
  std::vector<uint32_t> triangle_in_mesh_;  // index into the mesh's triangles (normals)
  std::vector<Analytic> analytic_;
  std::vector<const TriangleMesh*> object_mesh_;             // per object, or null
  std::vector<std::unique_ptr<TriangleMesh>> owned_meshes_;  // tessellated spheres
  std::vector<uint32_t> object_material_;
  std::vector<uint32_t> object_first_triangle_;  // unified index of each object's triangle 0
  // BVH leaf slots: primitive index and, for triangles, a copy in leaf order for locality.
  Bvh bvh_;
  TraversalVector<uint32_t> slot_primitive_;
  TraversalVector<TrianglePrecomputed> slot_triangles_;
  std::unique_ptr<EmbreeBackend, EmbreeBackendDeleter> embree_;
  std::string error_;
};

}  // namespace rvr
