#include "embree_backend.h"

#include <embree3/rtcore.h>

#include <cstring>
#include <limits>
#include <vector>

namespace rvr {

struct EmbreeBackend {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  const TraceGeometry* owner = nullptr;
  std::vector<uint32_t> geometry_base;  // per geomID: unified index of its primitive 0
  uint32_t analytic_geometry = RTC_INVALID_GEOMETRY_ID;

  static EmbreeBackend* create(const TraceGeometry& g, std::string& error);
  ~EmbreeBackend() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }

  // Our user-geometry callbacks: the analytic shapes through TraceGeometry::hit_analytic.
  static void bounds(const RTCBoundsFunctionArguments* args);
  static void intersect(const RTCIntersectFunctionNArguments* args);
  static void occluded(const RTCOccludedFunctionNArguments* args);
};

void EmbreeBackendDeleter::operator()(EmbreeBackend* backend) const {
  delete backend;
}

namespace {

// The intersect context carries where a CSG hit's extra data goes (Embree keeps only t, u, v).
struct QueryContext {
  RTCIntersectContext embree;
  HitRecord* hit;
};

Ray to_ray(const RTCRay& r) {
  return Ray{{r.org_x, r.org_y, r.org_z}, {r.dir_x, r.dir_y, r.dir_z}, r.tnear, r.tfar};
}

void set_ray(RTCRay& r, const Ray& ray) {
  r.org_x = ray.origin.x;
  r.org_y = ray.origin.y;
  r.org_z = ray.origin.z;
  r.dir_x = ray.dir.x;
  r.dir_y = ray.dir.y;
  r.dir_z = ray.dir.z;
  r.tnear = ray.tmin;
  r.tfar = ray.tmax;
  r.time = 0.0f;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
}

}  // namespace

void EmbreeBackend::bounds(const RTCBoundsFunctionArguments* args) {
  auto* self = static_cast<const EmbreeBackend*>(args->geometryUserPtr);
  Aabb b = TraceGeometry::analytic_bounds(self->owner->analytic_[args->primID]);
  *args->bounds_o = {b.lo.x, b.lo.y, b.lo.z, 0.0f, b.hi.x, b.hi.y, b.hi.z, 0.0f};
}

void EmbreeBackend::intersect(const RTCIntersectFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;  // only rtcIntersect1 is used
  auto* self = static_cast<const EmbreeBackend*>(args->geometryUserPtr);
  auto* rayhit = reinterpret_cast<RTCRayHit*>(args->rayhit);
  HitRecord h;
  if (!self->owner->hit_analytic(self->owner->analytic_[args->primID], to_ray(rayhit->ray),
                                 rayhit->ray.tfar, h))
    return;
  rayhit->ray.tfar = h.t;
  rayhit->hit.u = 0.0f;
  rayhit->hit.v = 0.0f;
  rayhit->hit.geomID = args->geomID;
  rayhit->hit.primID = args->primID;
  rayhit->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  // The last accepted analytic hit is the nearest one so far.
  auto* context = reinterpret_cast<QueryContext*>(args->context);
  context->hit->csg_leaf = h.csg_leaf;
  context->hit->csg_flip = h.csg_flip;
}

void EmbreeBackend::occluded(const RTCOccludedFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  auto* self = static_cast<const EmbreeBackend*>(args->geometryUserPtr);
  auto* ray = reinterpret_cast<RTCRay*>(args->ray);
  HitRecord h;
  if (self->owner->hit_analytic(self->owner->analytic_[args->primID], to_ray(*ray), ray->tfar, h))
    ray->tfar = -std::numeric_limits<float>::infinity();
}

EmbreeBackend* EmbreeBackend::create(const TraceGeometry& g, std::string& error) {
  auto backend = std::make_unique<EmbreeBackend>();
  backend->owner = &g;
  backend->device = rtcNewDevice(nullptr);
  if (!backend->device) {
    error = "Embree: cannot create a device (error " +
            std::to_string(int(rtcGetDeviceError(nullptr))) + ")";
    return nullptr;
  }
  backend->scene = rtcNewScene(backend->device);
  rtcSetSceneBuildQuality(backend->scene, g.embree_quality_ == EmbreeQuality::High
                                              ? RTC_BUILD_QUALITY_HIGH
                                              : RTC_BUILD_QUALITY_MEDIUM);
  for (size_t object = 0; object < g.object_mesh_.size(); ++object) {
    const TriangleMesh* mesh = g.object_mesh_[object];
    if (!mesh || mesh->triangles.empty()) continue;
    RTCGeometry geom = rtcNewGeometry(backend->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree's own buffers carry the padding its SIMD loads need after the last vertex.
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh->positions.size()));
    auto* indices = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(uint32_t), mesh->triangles.size()));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geom);
      error = "Embree: out of memory for a mesh of " + std::to_string(mesh->triangles.size()) +
              " triangles";
      return nullptr;
    }
    std::memcpy(vertices, mesh->positions.data(), mesh->positions.size() * 3 * sizeof(float));
    std::memcpy(indices, mesh->triangles.data(), mesh->triangles.size() * 3 * sizeof(uint32_t));
    rtcCommitGeometry(geom);
    uint32_t id = rtcAttachGeometry(backend->scene, geom);
    rtcReleaseGeometry(geom);
    if (backend->geometry_base.size() <= id) backend->geometry_base.resize(id + 1, 0);
    backend->geometry_base[id] = g.object_first_triangle_[object];
  }
  if (!g.analytic_.empty()) {
    RTCGeometry geom = rtcNewGeometry(backend->device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, unsigned(g.analytic_.size()));
    rtcSetGeometryUserData(geom, backend.get());
    rtcSetGeometryBoundsFunction(geom, &EmbreeBackend::bounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, &EmbreeBackend::intersect);
    rtcSetGeometryOccludedFunction(geom, &EmbreeBackend::occluded);
    rtcCommitGeometry(geom);
    uint32_t id = rtcAttachGeometry(backend->scene, geom);
    rtcReleaseGeometry(geom);
    backend->analytic_geometry = id;
    if (backend->geometry_base.size() <= id) backend->geometry_base.resize(id + 1, 0);
    backend->geometry_base[id] = uint32_t(g.triangles_.size());
  }
  rtcCommitScene(backend->scene);
  if (RTCError e = rtcGetDeviceError(backend->device); e != RTC_ERROR_NONE) {
    error = "Embree: building the scene failed (error " + std::to_string(int(e)) + ")";
    return nullptr;
  }
  return backend.release();
}

EmbreeBackend* make_embree_backend(const TraceGeometry& geometry, std::string& error) {
  return EmbreeBackend::create(geometry, error);
}

bool embree_closest(const EmbreeBackend& backend, const Ray& ray, HitRecord& hit) {
  QueryContext context;
  rtcInitIntersectContext(&context.embree);
  context.hit = &hit;
  RTCRayHit rayhit;
  set_ray(rayhit.ray, ray);
  rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(backend.scene, &context.embree, &rayhit);
  if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rayhit.ray.tfar;
  hit.primitive = backend.geometry_base[rayhit.hit.geomID] + rayhit.hit.primID;
  hit.u = rayhit.hit.u;  // Embree's barycentrics: p = (1-u-v) v0 + u v1 + v v2, as ours
  hit.v = rayhit.hit.v;
  return true;
}

bool embree_occluded(const EmbreeBackend& backend, const Ray& ray) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r;
  set_ray(r, ray);
  rtcOccluded1(backend.scene, &context, &r);
  return r.tfar < 0.0f;
}

std::string embree_version() {
  return RTC_VERSION_STRING;
}

}  // namespace rvr
