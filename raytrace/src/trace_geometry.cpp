#include "rvr/raytrace/trace_geometry.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <utility>
#include <variant>

#include "embree_backend.h"
#include "rvr/core/check.h"
#include "rvr/core/prefetch.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/shape_geometry.h"
#include "rvr/raytrace/bvh_packet.h"
#include "rvr/raytrace/packet_slots.h"
#include "rvr/raytrace/primary_rays.h"
#include "rvr/raytrace/traversal_kernels.h"

namespace rvr {
TraceGeometry::TraceGeometry(const Scene& scene, SphereMode spheres, int sphere_segments,
                             AccelKind accel, TriangleTest triangle_test, std::optional<Isa> isa,
                             EmbreeQuality embree_quality)
    : accel_(accel), triangle_test_(triangle_test), embree_quality_(embree_quality) {
  size_t n_objects = scene.objects.size();
  object_mesh_.assign(n_objects, nullptr);
  object_material_.resize(n_objects);
  size_t total_triangles = 0;
  for (const Object& o : scene.objects) total_triangles += o.mesh.triangle_count();
  triangles_.reserve(total_triangles);
  triangle_object_.reserve(total_triangles);
  triangle_id_.reserve(total_triangles);
  triangle_in_mesh_.reserve(total_triangles);

  object_first_triangle_.assign(n_objects, 0);
  object_analytic_.assign(n_objects, kNoPrimitive);
  object_triangle_count_.assign(n_objects, 0);
  // Every triangle the tracer sees is named by its index in its mesh (a tessellated sphere's
  // facets too, as the z-buffers name them under SphereMode::Mesh).
  auto add_mesh = [&](uint32_t object, const TriangleMesh& mesh) {
    object_mesh_[object] = &mesh;
    object_first_triangle_[object] = uint32_t(triangles_.size());
    object_triangle_count_[object] = uint32_t(mesh.triangles.size());
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
      const glm::uvec3& t = mesh.triangles[i];
      triangles_.push_back(
          precompute_triangle(mesh.positions[t.x], mesh.positions[t.y], mesh.positions[t.z]));
      for (int c = 0; c < 3; ++c) bounds_.grow(mesh.positions[t[c]]);
      triangle_object_.push_back(object);
      triangle_id_.push_back(uint32_t(i));
      triangle_in_mesh_.push_back(uint32_t(i));
    }
  };

  const TessellationOptions tessellation{sphere_segments, spheres == SphereMode::Mesh};
  for (uint32_t id = 0; id < n_objects; ++id) {
    const Object& o = scene.objects[id];
    object_material_[id] = o.material;
    visit_shape(o, [&](const auto& shape) {
      if constexpr (requires { shape.traced(); }) {
        if (shape.traced_analytically(tessellation)) {
          object_analytic_[id] = uint32_t(analytic_.size());
          // A CSG solid's leaves follow --spheres too (traced(options)).
          if constexpr (requires { shape.traced(tessellation); })
            analytic_.push_back({id, TracedShape(shape.traced(tessellation))});
          else
            analytic_.push_back({id, TracedShape(shape.traced())});
          return;
        }
      }
      TriangleForm form = shape.triangle_form(tessellation);
      if (form.made) owned_meshes_.push_back(std::move(form.made));
      add_mesh(id, *form.mesh);
    });
  }

  for (size_t k = 0; k < analytic_.size(); ++k) {
    bounds_.grow(analytic_bounds(analytic_[k]));
    if (std::holds_alternative<CsgSolid::Traced>(analytic_[k].shape))
      csg_primitives_.push_back(uint32_t(triangles_.size() + k));
    if (!triangle_form_exact(analytic_[k]))
      approximated_primitives_.push_back(uint32_t(triangles_.size() + k));
  }

  if (accel_ == AccelKind::Embree) {
    embree_.reset(make_embree_backend(*this, error_.message));
    return;
  }
  if (accel_ == AccelKind::None) return;
  if (accel_ == AccelKind::Bvh) {
    // Triangles in the wide BVH, for the SIMD kernels; analytic shapes in a binary one.
    if (!isa) {
      Expected<Isa> selected = selected_isa();
      if (!selected) {
        error_ = selected.error();
        return;
      }
      isa = *selected;
    }
    if (!cpu_supports(*isa)) {
      error_ = bad_input(std::string("this CPU cannot run the ") + to_string(*isa) + " kernels");
      return;
    }
    kernels_ = &traversal_kernels(*isa);
    if (!triangles_.empty()) {
      Expected<WideBvh> wide = WideBvh::build(triangles_);
      if (!wide) {
        error_ = wide.error();
        return;
      }
      wide_ = std::move(wide).value();
    }
    std::vector<Aabb> bounds(analytic_.size());
    for (size_t k = 0; k < analytic_.size(); ++k) bounds[k] = analytic_bounds(analytic_[k]);
    bvh_ = Bvh::build(bounds);
    slot_primitive_.assign(bvh_.primitive_order().begin(), bvh_.primitive_order().end());
    return;
  }
  std::vector<Aabb> bounds(primitive_count());
  for (size_t i = 0; i < triangles_.size(); ++i) {
    const TrianglePrecomputed& t = triangles_[i];
    bounds[i].grow(t.v0);
    bounds[i].grow(t.v0 + t.e1);
    bounds[i].grow(t.v0 + t.e2);
  }
  for (size_t k = 0; k < analytic_.size(); ++k)
    bounds[triangles_.size() + k] = analytic_bounds(analytic_[k]);
  bvh_ = Bvh::build(bounds);
  slot_primitive_.assign(bvh_.primitive_order().begin(), bvh_.primitive_order().end());
  slot_triangles_.resize(slot_primitive_.size());
  for (size_t s = 0; s < slot_primitive_.size(); ++s) {
    if (slot_primitive_[s] < triangles_.size()) slot_triangles_[s] = triangles_[slot_primitive_[s]];
  }
}

TraceGeometry::~TraceGeometry() = default;

bool TraceGeometry::triangle_form_exact(const Analytic& a) {
  return std::visit(
      [](const auto& shape) { return std::decay_t<decltype(shape)>::kTriangleFormExact; }, a.shape);
}

Aabb TraceGeometry::analytic_bounds(const Analytic& a) {
  std::vector<BoundingBall> balls;
  std::visit([&](const auto& shape) { shape.bounding_balls(balls); }, a.shape);
  Aabb b;
  for (const BoundingBall& ball : balls) {
    b.grow(ball.centre - glm::vec3(ball.radius));
    b.grow(ball.centre + glm::vec3(ball.radius));
  }
  return b;
}

std::vector<Aabb> TraceGeometry::approximated_bounds() const {
  std::vector<Aabb> bounds;
  const uint32_t n_triangles = uint32_t(triangles_.size());
  for (uint32_t p : approximated_primitives_)
    bounds.push_back(analytic_bounds(analytic_[p - n_triangles]));
  return bounds;
}

std::vector<uint32_t> TraceGeometry::approximated_objects() const {
  std::vector<uint32_t> objects;
  const uint32_t n_triangles = uint32_t(triangles_.size());
  for (uint32_t p : approximated_primitives_) objects.push_back(analytic_[p - n_triangles].object);
  std::sort(objects.begin(), objects.end());
  objects.erase(std::unique(objects.begin(), objects.end()), objects.end());
  return objects;
}

int TraceGeometry::embree_packet_width() const {
  return embree_ ? rvr::embree_packet_width(*embree_) : 0;
}

size_t TraceGeometry::acceleration_bytes() const {
  if (embree_) return embree_build_bytes(*embree_);
  return wide_.bytes() + bvh_.nodes().size() * sizeof(BvhNode) +
         slot_primitive_.size() * sizeof(uint32_t) +
         slot_triangles_.size() * sizeof(TrianglePrecomputed);
}

namespace {

// A hit of an analytic shape as closest() reports it, as primitive p.
HitRecord shape_hit_record(const ShapeHit& h, uint32_t p) {
  HitRecord hit;
  hit.t = h.t;
  hit.csg_leaf = h.part;
  hit.csg_flip = h.flip;
  hit.primitive = p;
  return hit;
}

}  // namespace

bool TraceGeometry::hit_analytic(const Analytic& a, const Ray& ray, float t_max,
                                 HitRecord& hit) const {
  Ray r = ray;
  r.tmax = t_max;
  ShapeHit h;
  if (!std::visit([&](const auto& shape) { return shape.intersect(r, h); }, a.shape)) return false;
  hit.t = h.t;
  hit.csg_leaf = h.part;
  hit.csg_flip = h.flip;
  return true;
}

struct MollerTrumboreTest {
  bool operator()(const Ray& r, const TrianglePrecomputed& t, TriangleHit& h) const {
    return intersect_triangle_mt(r, t, h);
  }
};
struct ChapterTest {
  bool operator()(const Ray& r, const TrianglePrecomputed& t, TriangleHit& h) const {
    return intersect_triangle_chapter(r, t, h);
  }
};

// A hit at t is nearer than the best so far when t is smaller or, at the same t, its primitive
// index is lower: the result does not depend on the order primitives are tested in. A test
// accepting t < limit is given the float after t_max so that t == t_max gets through.
inline float tie_limit(float t_max) {
  return std::nextafter(t_max, INFINITY);
}
inline bool nearer(float t, uint32_t p, float t_max, uint32_t best) {
  return t < t_max || (t == t_max && p < best);
}

template <class TriangleTestFn, bool kAnyHit>
bool TraceGeometry::query(const Ray& ray, HitRecord& hit, TraversalCounters& counters) const {
  TriangleTestFn test;
  const uint32_t n_triangles = uint32_t(triangles_.size());
  bool found = false;
  float t_max = ray.tmax;
  Ray r = ray;
  // Tests primitive p (whose triangle, if it is one, is `tri`); true when it is a new nearest.
  auto test_primitive = [&](uint32_t p, const TrianglePrecomputed& tri) {
    float limit = found && !kAnyHit ? tie_limit(t_max) : t_max;
    if (p < n_triangles) {
      r.tmax = limit;
      TriangleHit th;
      if (!test(r, tri, th) || (found && !nearer(th.t, p, t_max, hit.primitive))) return false;
      t_max = th.t;
      hit = HitRecord{};
      hit.t = th.t;
      hit.u = th.u;
      hit.v = th.v;
    } else {
      HitRecord h;
      if (!hit_analytic(analytic_[p - n_triangles], ray, limit, h) ||
          (found && !nearer(h.t, p, t_max, hit.primitive)))
        return false;
      t_max = h.t;
      hit = h;
    }
    hit.primitive = p;
    found = true;
    return true;
  };

  if (accel_ == AccelKind::None) {
    // The chapter's loop: every object, keep the nearest.
    uint32_t n = uint32_t(primitive_count());
    static const TrianglePrecomputed kUnused{};
    for (uint32_t p = 0; p < n; ++p) {
      counters.primitive_tests++;
      if (test_primitive(p, p < n_triangles ? triangles_[p] : kUnused) && kAnyHit) return true;
    }
    return found;
  }
  bvh_.traverse(
      ray, t_max,
      [&](uint32_t first, uint32_t count, float&) {
        for (uint32_t s = first; s < first + count; ++s) {
          if (test_primitive(slot_primitive_[s], slot_triangles_[s]) && kAnyHit) return true;
        }
        return false;
      },
      counters);
  return found;
}

// The analytic shapes of the wide-BVH configuration, nearer than t_max (a triangle hit there has
// a lower primitive index, so it wins a tie).
template <bool kAnyHit>
bool TraceGeometry::query_analytic(const Ray& ray, float t_max, HitRecord& hit,
                                   TraversalCounters* counters) const {
  if (bvh_.empty()) return false;
  const uint32_t n_triangles = uint32_t(triangles_.size());
  bool found = false;
  TraversalCounters unused;
  float limit = t_max;
  bvh_.traverse(
      ray, limit,
      [&](uint32_t first, uint32_t count, float& t) {
        for (uint32_t s = first; s < first + count; ++s) {
          uint32_t p = n_triangles + slot_primitive_[s];
          HitRecord h;
          float lim = found && !kAnyHit ? tie_limit(t) : t;
          if (!hit_analytic(analytic_[slot_primitive_[s]], ray, lim, h)) continue;
          if (found && !nearer(h.t, p, t, hit.primitive)) continue;
          hit = h;
          hit.primitive = p;
          t = h.t;
          found = true;
          if (kAnyHit) return true;
        }
        return false;
      },
      counters ? *counters : unused);
  return found;
}

template <bool kCount>
bool TraceGeometry::closest_wide(const Ray& ray, HitRecord& hit,
                                 TraversalCounters* counters) const {
  KernelRay kr{{ray.origin.x, ray.origin.y, ray.origin.z},
               {ray.dir.x, ray.dir.y, ray.dir.z},
               ray.tmin,
               ray.tmax};
  KernelHit kh;
  bool found = false;
  if (!wide_.empty()) {
    if (kCount) {
      KernelCounters kc;
      found = kernels_->closest_counted(wide_.view(), kr, kh, kc);
      counters->nodes_visited += kc.nodes;
      counters->primitive_tests += kc.tests;
    } else {
      found = kernels_->closest(wide_.view(), kr, kh);
    }
  }
  if (found) {
    hit.t = kh.t;
    hit.u = kh.u;
    hit.v = kh.v;
    hit.primitive = kh.primitive;
  }
  if (!analytic_.empty() && query_analytic<false>(ray, found ? kh.t : ray.tmax, hit, counters))
    found = true;
  return found;
}

template <bool kCount>
bool TraceGeometry::occluded_wide(const Ray& ray, TraversalCounters* counters) const {
  KernelRay kr{{ray.origin.x, ray.origin.y, ray.origin.z},
               {ray.dir.x, ray.dir.y, ray.dir.z},
               ray.tmin,
               ray.tmax};
  if (!wide_.empty()) {
    if (kCount) {
      KernelCounters kc;
      bool hit = kernels_->occluded_counted(wide_.view(), kr, kc);
      counters->nodes_visited += kc.nodes;
      counters->primitive_tests += kc.tests;
      if (hit) return true;
    } else if (kernels_->occluded(wide_.view(), kr)) {
      return true;
    }
  }
  HitRecord unused;
  return !analytic_.empty() && query_analytic<true>(ray, ray.tmax, unused, counters);
}

bool TraceGeometry::closest(const Ray& ray, HitRecord& hit, TraversalCounters& counters) const {
  if (embree_) return embree_closest(*embree_, ray, hit);
  if (kernels_) return closest_wide<true>(ray, hit, &counters);
  if (triangle_test_ == TriangleTest::Chapter) return query<ChapterTest, false>(ray, hit, counters);
  return query<MollerTrumboreTest, false>(ray, hit, counters);
}

bool TraceGeometry::closest(const Ray& ray, HitRecord& hit) const {
  if (kernels_) return closest_wide<false>(ray, hit, nullptr);
  TraversalCounters unused;
  return closest(ray, hit, unused);
}

void TraceGeometry::closest_packet(const RayPacket& packet, HitRecord* hits,
                                   TraversalCounters* counters) const {
  auto ray = [&](int i) {
    return Ray{{packet.origin[0], packet.origin[1], packet.origin[2]},
               {packet.dir[0][i], packet.dir[1][i], packet.dir[2][i]},
               packet.tmin,
               packet.tmax};
  };
  if (embree_) {
    embree_closest_packet(*embree_, packet, hits);
    if (counters) std::fill_n(counters, packet.count, TraversalCounters{});
    return;
  }
  if (!kernels_) {
    TraversalCounters unused;
    for (int i = 0; i < packet.count; ++i) {
      hits[i] = HitRecord{};
      if (counters) counters[i] = TraversalCounters{};
      closest(ray(i), hits[i], counters ? counters[i] : unused);
    }
    return;
  }
  PacketSlots<KernelHit> kh;       // the kernel writes every ray's, a miss included
  PacketSlots<KernelCounters> kc;  // the kernel adds to them: zeroed as far as the packet goes
  if (counters) std::fill_n(kc.data(), packet.count, KernelCounters{});
  if (wide_.empty()) {
    for (int i = 0; i < packet.count; ++i) hits[i] = HitRecord{};
  } else {
    kernels_->closest_packet(wide_.view(), packet, kh.data(), counters ? kc.data() : nullptr);
    for (int i = 0; i < packet.count; ++i) {
      const KernelHit& k = kh[i];
      hits[i] = k.primitive != kUnusedLane ? HitRecord{k.t, k.primitive, k.u, k.v} : HitRecord{};
    }
  }
  if (counters)
    for (int i = 0; i < packet.count; ++i) counters[i] = {kc[i].nodes, kc[i].tests};
  if (!analytic_.empty()) closest_analytic_packet(packet, hits, counters);
}

// Shape `a` for the rays of bit mask `rays`, each limited by its t_max[k] and, once it has an
// analytic hit (bit k of `found`), by closest()'s tie rule against it; a nearer hit replaces
// hits[k] and lowers t_max[k]. The shape's kind is dispatched once for all the rays, and each ray
// meets the shapes in the order of the calls, as a single ray's query would.
void TraceGeometry::nearest_shape_hits(const RayPacket& packet, uint64_t rays, uint32_t a,
                                       float* t_max, uint64_t& found, HitRecord* hits) const {
  const uint32_t p = uint32_t(triangles_.size()) + a;
  std::visit(
      [&](const auto& shape) {
        for (uint64_t m = rays; m != 0; m &= m - 1) {
          const int k = __builtin_ctzll(m);
          const uint64_t bit = uint64_t(1) << k;
          const float t = t_max[k];
          Ray ray = PrimaryRays::ray_of(packet, k);
          ray.tmax = found & bit ? tie_limit(t) : t;
          ShapeHit h;
          if (!shape.intersect(ray, h)) continue;
          if ((found & bit) && !nearer(h.t, p, t, hits[k].primitive)) continue;
          hits[k] = shape_hit_record(h, p);
          t_max[k] = h.t;
          found |= bit;
        }
      },
      analytic_[a].shape);
}

// query_analytic<false> for every ray of the packet, the analytic shapes' tree walked once for
// the packet: the rays' limits start at their triangle hits (a triangle wins a tie, having the
// lower index), and a shape's hit replaces the ray's hit when nearer.
void TraceGeometry::closest_analytic_packet(const RayPacket& packet, HitRecord* hits,
                                            TraversalCounters* counters) const {
  static_assert(kPacketRays <= PacketBoxData::kMaxRays, "a packet's rays fit one bit mask");
  if (bvh_.empty()) return;
  const float* const dir[3] = {packet.dir[0], packet.dir[1], packet.dir[2]};
  const PacketBoxData rays(packet.origin, dir, packet.count, packet.tmin);
  float t_max[PacketBoxData::kMaxRays];
  for (int k = 0; k < PacketBoxData::kMaxRays; ++k)
    t_max[k] = k < packet.count && hits[k].primitive != kNoPrimitive ? hits[k].t : packet.tmax;
  uint64_t found = 0;  // rays with an analytic hit so far
  auto leaf = [&](uint32_t first, uint32_t count, uint64_t entered) {
    for (uint32_t s = first; s < first + count; ++s)
      nearest_shape_hits(packet, entered, slot_primitive_[s], t_max, found, hits);
  };
  if (counters)
    traverse_packet<true>(bvh_, rays, t_max, leaf, counters);
  else
    traverse_packet<false>(bvh_, rays, t_max, leaf, nullptr);
}

bool TraceGeometry::occluded(const Ray& ray, TraversalCounters& counters) const {
  if (embree_) return embree_occluded(*embree_, ray);
  if (kernels_) return occluded_wide<true>(ray, &counters);
  HitRecord hit;
  if (triangle_test_ == TriangleTest::Chapter) return query<ChapterTest, true>(ray, hit, counters);
  return query<MollerTrumboreTest, true>(ray, hit, counters);
}

bool TraceGeometry::occluded(const Ray& ray) const {
  if (kernels_) return occluded_wide<false>(ray, nullptr);
  TraversalCounters unused;
  return occluded(ray, unused);
}

SurfaceHit TraceGeometry::surface(const Ray& ray, const HitRecord& hit) const {
  SurfaceHit s;
  s.t = hit.t;
  s.position = ray.origin + hit.t * ray.dir;
  const uint32_t n_triangles = uint32_t(triangles_.size());
  if (hit.primitive < n_triangles) {
    uint32_t p = hit.primitive;
    const TrianglePrecomputed& tri = triangles_[p];
    s.object = triangle_object_[p];
    s.primitive = triangle_id_[p];
    s.u = hit.u;
    s.v = hit.v;
    s.geometric_normal = glm::normalize(glm::cross(tri.e1, tri.e2));
    s.shading_normal = s.geometric_normal;
    const TriangleMesh* mesh = object_mesh_[s.object];
    if (mesh->smooth()) {
      const glm::uvec3& v = mesh->triangles[triangle_in_mesh_[p]];
      glm::vec3 n = (1.0f - hit.u - hit.v) * mesh->normals[v.x] + hit.u * mesh->normals[v.y] +
                    hit.v * mesh->normals[v.z];
      float len = glm::length(n);
      if (len > 0.0f) s.shading_normal = n / len;
    }
  } else {
    const Analytic& a = analytic_[hit.primitive - n_triangles];
    s.object = a.object;
    s.primitive = 0;
    const ShapeHit shape_hit{hit.t, hit.csg_leaf, hit.csg_flip};
    s.geometric_normal = std::visit(
        [&](const auto& shape) { return shape.normal_at(s.position, shape_hit); }, a.shape);
    s.geometric_normal = glm::normalize(s.geometric_normal);
    s.shading_normal = s.geometric_normal;
    // A CSG solid of tessellated leaves: interpolated normals on flat triangles.
    if (const auto* csg = std::get_if<CsgSolid::Traced>(&a.shape))
      s.geometric_normal = csg->geometric_normal_at(s.position, shape_hit);
  }
  s.material = object_material_[s.object];
  return s;
}

std::pair<uint32_t, uint32_t> TraceGeometry::hit_ids(const HitRecord& hit) const {
  const uint32_t n_triangles = uint32_t(triangles_.size());
  RVR_DCHECK(hit.primitive < n_triangles + analytic_.size(), "hit primitive ", hit.primitive,
             " of ", n_triangles, " triangles and ", analytic_.size(), " analytic objects");
  if (hit.primitive < n_triangles)
    return {triangle_object_[hit.primitive], triangle_id_[hit.primitive]};
  return {analytic_[hit.primitive - n_triangles].object, 0u};
}

TriangleSurfaceData TraceGeometry::triangle_surface_data(uint32_t p) const {
  RVR_DCHECK(p < triangles_.size(), "triangle ", p, " of ", triangles_.size());
  TriangleSurfaceData d;
  d.triangle = &triangles_[p];
  d.object = triangle_object_[p];
  d.primitive = triangle_id_[p];
  d.material = object_material_[d.object];
  const TriangleMesh* mesh = object_mesh_[d.object];
  if (mesh->smooth()) {
    const glm::uvec3& v = mesh->triangles[triangle_in_mesh_[p]];
    for (int c = 0; c < 3; ++c) d.normal[c] = &mesh->normals[v[c]];
  }
  return d;
}

void TraceGeometry::fetch_surface_data(const HitRecord* hits, int n, bool ids_only) const {
  if (triangles_.size() < kFetchAheadTriangles) return;
  const uint32_t n_triangles = uint32_t(triangles_.size());
  auto each_triangle = [&](auto&& fetch) {
    for (int k = 0; k < n; ++k)
      if (hits[k].primitive < n_triangles && (k == 0 || hits[k].primitive != hits[k - 1].primitive))
        fetch(hits[k].primitive);
  };
  each_triangle([&](uint32_t p) {
    prefetch(&triangles_[p]);
    prefetch(&triangle_object_[p]);
    prefetch(&triangle_id_[p]);
    prefetch(&triangle_in_mesh_[p]);
  });
  if (ids_only) return;
  each_triangle([&](uint32_t p) {
    const TriangleMesh* mesh = object_mesh_[triangle_object_[p]];
    if (mesh->smooth()) prefetch(&mesh->triangles[triangle_in_mesh_[p]]);
  });
  each_triangle([&](uint32_t p) {
    const TriangleMesh* mesh = object_mesh_[triangle_object_[p]];
    if (!mesh->smooth()) return;
    const glm::uvec3& v = mesh->triangles[triangle_in_mesh_[p]];
    for (int c = 0; c < 3; ++c) prefetch(&mesh->normals[v[c]]);
  });
}

bool TraceGeometry::intersect_named(const Ray& ray, uint32_t object, uint32_t primitive,
                                    HitRecord& hit, TraversalCounters& counters) const {
  if (object >= object_analytic_.size()) return false;
  const uint32_t n_triangles = uint32_t(triangles_.size());
  hit = HitRecord{};
  if (uint32_t a = object_analytic_[object]; a != kNoPrimitive) {
    counters.primitive_tests++;
    if (!hit_analytic(analytic_[a], ray, ray.tmax, hit)) return false;
    hit.primitive = n_triangles + a;
    return true;
  }
  // A mesh's ids name its triangle (0 triangles: an object without a mesh).
  if (primitive >= object_triangle_count_[object]) return false;
  const uint32_t p = object_first_triangle_[object] + primitive;
  TriangleHit th;
  counters.primitive_tests++;
  const bool ok = triangle_test_ == TriangleTest::Chapter
                      ? intersect_triangle_chapter(ray, triangles_[p], th)
                      : intersect_triangle_mt(ray, triangles_[p], th);
  if (!ok) return false;
  hit.t = th.t;
  hit.u = th.u;
  hit.v = th.v;
  hit.primitive = p;
  return true;
}

// intersect_named for the rays of `rays` (bit k: ray k), each naming an object traced
// analytically: shape by shape, its kind dispatched once for the rays that name it. Returns the
// rays that hit.
uint64_t TraceGeometry::intersect_named_shapes(const RayPacket& packet, const uint32_t* object,
                                               uint64_t rays, HitRecord* hits,
                                               TraversalCounters* counters) const {
  const uint32_t n_triangles = uint32_t(triangles_.size());
  uint64_t found = 0;
  while (rays != 0) {
    const uint32_t a = object_analytic_[object[__builtin_ctzll(rays)]];
    std::visit(
        [&](const auto& shape) {
          for (uint64_t m = rays; m != 0; m &= m - 1) {
            const int k = __builtin_ctzll(m);
            if (object_analytic_[object[k]] != a) continue;
            rays &= ~(uint64_t(1) << k);
            counters[k].primitive_tests++;
            hits[k] = HitRecord{};
            ShapeHit h;
            if (!shape.intersect(PrimaryRays::ray_of(packet, k), h)) continue;
            hits[k] = shape_hit_record(h, n_triangles + a);
            found |= uint64_t(1) << k;
          }
        },
        analytic_[a].shape);
  }
  return found;
}

uint64_t TraceGeometry::intersect_named_packet(const RayPacket& packet, const uint32_t* object,
                                               const uint32_t* primitive, uint64_t wanted,
                                               HitRecord* hits, TraversalCounters* counters) const {
  static_assert(sizeof(TrianglePrecomputed) == 9 * sizeof(float), "v0, e1, e2: 9 floats");
  const bool simd = kernels_ && triangle_test_ == TriangleTest::MollerTrumbore;
  NamedTriangles named;
  named.triangles = reinterpret_cast<const float*>(triangles_.data());
  uint64_t found = 0;
  uint64_t named_rays = 0;         // the rays naming one triangle of a mesh, for the kernel
  uint64_t analytic_rays = 0;      // the rays naming a shape traced analytically
  auto named_alone = [&](int k) {  // intersect_named itself, for ray k
    if (intersect_named(PrimaryRays::ray_of(packet, k), object[k], primitive[k], hits[k],
                        counters[k]))
      found |= uint64_t(1) << k;
  };
  // The rays naming one triangle of a mesh, looked up in flat per-object tables eight at a time;
  // the others one by one.
  const uint64_t rays = wanted & packet.all();
  if (simd)
    named_rays = kernels_->name_triangles(
        TriangleNames{object_first_triangle_.data(), object_triangle_count_.data(),
                      uint32_t(object_triangle_count_.size())},
        object, primitive, rays, named.index);
  for (uint64_t m = rays & ~named_rays; m != 0; m &= m - 1) {
    const int k = __builtin_ctzll(m);
    const uint32_t o = object[k];
    if (o < object_analytic_.size() && object_analytic_[o] != kNoPrimitive)
      analytic_rays |= uint64_t(1) << k;  // below, shape by shape
    else
      named_alone(k);
  }
  found |= intersect_named_shapes(packet, object, analytic_rays, hits, counters);
  if (named_rays == 0) return found;
  named.rays = named_rays;
  NamedHits kernel_hits;
  kernels_->intersect_named(packet, named, kernel_hits);
  // Near an edge: decided in double, as intersect_named does.
  for (uint64_t m = kernel_hits.near_edge; m != 0; m &= m - 1) named_alone(__builtin_ctzll(m));
  for (uint64_t m = named_rays & ~kernel_hits.near_edge; m != 0; m &= m - 1) {
    const int k = __builtin_ctzll(m);
    counters[k].primitive_tests++;
    hits[k] = HitRecord{};
    if (!((kernel_hits.hit >> k) & 1)) continue;
    hits[k].t = kernel_hits.t[k];
    hits[k].u = kernel_hits.u[k];
    hits[k].v = kernel_hits.v[k];
    hits[k].primitive = named.index[k];
  }
  return found | kernel_hits.hit;
}

bool TraceGeometry::closest_approximated(const Ray& ray, HitRecord& hit,
                                         TraversalCounters& counters) const {
  return closest_among(approximated_primitives_, ray, hit, counters);
}

uint64_t TraceGeometry::closest_approximated_packet(const RayPacket& packet, uint64_t rays,
                                                    HitRecord* hits,
                                                    TraversalCounters* counters) const {
  float t_max[kPacketRays];
  for (uint64_t m = rays; m != 0; m &= m - 1) {
    const int k = __builtin_ctzll(m);
    t_max[k] = packet.tmax;
    counters[k].primitive_tests += approximated_primitives_.size();
  }
  uint64_t found = 0;
  for (uint32_t p : approximated_primitives_)
    nearest_shape_hits(packet, rays, p - uint32_t(triangles_.size()), t_max, found, hits);
  return found;
}

bool TraceGeometry::closest_among(const std::vector<uint32_t>& primitives, const Ray& ray,
                                  HitRecord& hit, TraversalCounters& counters) const {
  const uint32_t n_triangles = uint32_t(triangles_.size());
  bool found = false;
  for (uint32_t p : primitives) {
    HitRecord h;
    counters.primitive_tests++;
    if (!hit_analytic(analytic_[p - n_triangles], ray, found ? tie_limit(hit.t) : ray.tmax, h))
      continue;
    if (found && !nearer(h.t, p, hit.t, hit.primitive)) continue;
    hit = h;
    hit.primitive = p;
    found = true;
  }
  return found;
}

}  // namespace rvr
