// The Embree plugin (embree_abi.h): Embree's BVH and watertight triangle test for meshes, the
// tracer's own intersection code (as Embree user geometry, through the callbacks of
// EmbreeSceneInput) for spheres, squares and CSG. Built as librvr_embree.so, the one part of
// rvr that links Embree.
#include <embree3/rtcore.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "embree_abi.h"
#include "rvr/core/check.h"
#include "rvr/core/ray.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  // The analytic shapes' callbacks and their user pointer (the TraceGeometry).
  const void* user = nullptr;
  Aabb (*analytic_bounds)(const void*, uint32_t) = nullptr;
  bool (*hit_analytic)(const void*, uint32_t, const Ray&, HitRecord&) = nullptr;
  size_t analytic_count = 0;
  std::vector<uint32_t> geometry_base;  // per geomID: unified index of its primitive 0
  int packet_width = 8;  // rtcIntersect8 or rtcIntersect16: the widest this device runs natively
  // What the device holds, as its memory monitor reports allocations (+) and frees (-); and of
  // it, what the scene's build added and kept: its BVH and the triangle data in its leaves.
  std::atomic<int64_t> device_bytes{0};
  size_t build_bytes = 0;

  static EmbreeScene* create(const EmbreeSceneInput& input, std::string& error);
  ~EmbreeScene() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }

  static bool monitor(void* user, ssize_t bytes, bool /*post*/) {
    static_cast<EmbreeScene*>(user)->device_bytes += int64_t(bytes);
    return true;  // never refuse an allocation
  }

  // Embree's user-geometry callbacks: the analytic shapes through the tracer's callbacks.
  static void bounds(const RTCBoundsFunctionArguments* args);
  static void intersect(const RTCIntersectFunctionNArguments* args);
  static void occluded(const RTCOccludedFunctionNArguments* args);
};

namespace {

// The intersect context carries where a CSG hit's extra data goes (Embree keeps only t, u, v):
// hits[ray id] (ray ids are lane numbers in a packet, 0 for a single ray).
struct QueryContext {
  RTCIntersectContext embree;
  HitRecord* hits;
};

// Lane i of a packet of N rays (N = 1 for a single ray).
Ray lane_ray(RTCRayN* rays, unsigned N, unsigned i) {
  return Ray{{RTCRayN_org_x(rays, N, i), RTCRayN_org_y(rays, N, i), RTCRayN_org_z(rays, N, i)},
             {RTCRayN_dir_x(rays, N, i), RTCRayN_dir_y(rays, N, i), RTCRayN_dir_z(rays, N, i)},
             RTCRayN_tnear(rays, N, i),
             RTCRayN_tfar(rays, N, i)};
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

void EmbreeScene::bounds(const RTCBoundsFunctionArguments* args) {
  auto* self = static_cast<const EmbreeScene*>(args->geometryUserPtr);
  RVR_CHECK(args->primID < self->analytic_count,
            "Embree asks for the bounds of an analytic object it was given: ", args->primID);
  Aabb b = self->analytic_bounds(self->user, args->primID);
  *args->bounds_o = {b.lo.x, b.lo.y, b.lo.z, 0.0f, b.hi.x, b.hi.y, b.hi.z, 0.0f};
}

// Called for one ray or a packet of N (args->valid says which lanes are live).
void EmbreeScene::intersect(const RTCIntersectFunctionNArguments* args) {
  auto* self = static_cast<const EmbreeScene*>(args->geometryUserPtr);
  auto* context = reinterpret_cast<QueryContext*>(args->context);
  const unsigned N = args->N;
  RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, N);
  RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, N);
  for (unsigned i = 0; i < N; ++i) {
    if (!args->valid[i]) continue;
    const Ray ray = lane_ray(rays, N, i);
    HitRecord h;
    if (!self->hit_analytic(self->user, args->primID, ray, h)) continue;
    RTCRayN_tfar(rays, N, i) = h.t;
    RTCHitN_u(hits, N, i) = 0.0f;
    RTCHitN_v(hits, N, i) = 0.0f;
    RTCHitN_geomID(hits, N, i) = args->geomID;
    RTCHitN_primID(hits, N, i) = args->primID;
    RTCHitN_instID(hits, N, i, 0) = RTC_INVALID_GEOMETRY_ID;
    // The last accepted analytic hit is the nearest one so far.
    HitRecord& out = context->hits[RTCRayN_id(rays, N, i)];
    out.csg_leaf = h.csg_leaf;
    out.csg_flip = h.csg_flip;
  }
}

void EmbreeScene::occluded(const RTCOccludedFunctionNArguments* args) {
  auto* self = static_cast<const EmbreeScene*>(args->geometryUserPtr);
  const unsigned N = args->N;
  RTCRayN* rays = args->ray;
  for (unsigned i = 0; i < N; ++i) {
    if (!args->valid[i]) continue;
    const Ray ray = lane_ray(rays, N, i);
    HitRecord h;
    if (self->hit_analytic(self->user, args->primID, ray, h))
      RTCRayN_tfar(rays, N, i) = -std::numeric_limits<float>::infinity();
  }
}

namespace {

// Embree's device configuration: when RVR_ISA forces our kernels to an instruction set, Embree
// is held to the same one (its max_isa), so that a forced comparison races equals. Unset, each
// chooses from the CPU.
std::string device_config(const char* extra) {
  std::string config = extra;
  const char* forced = std::getenv("RVR_ISA");
  const std::string isa = forced ? forced : "";
  const char* embree_isa = isa == "sse"      ? "sse4.2"
                           : isa == "avx2"   ? "avx2"
                           : isa == "avx512" ? "avx512"
                                             : nullptr;
  if (embree_isa) config += std::string(config.empty() ? "" : ",") + "max_isa=" + embree_isa;
  return config;
}

}  // namespace

EmbreeScene* EmbreeScene::create(const EmbreeSceneInput& input, std::string& error) {
  auto backend = std::make_unique<EmbreeScene>();
  backend->user = input.user;
  backend->analytic_bounds = input.analytic_bounds;
  backend->hit_analytic = input.hit_analytic;
  backend->analytic_count = input.analytic_count;
  backend->device = rtcNewDevice(device_config("").c_str());
  if (!backend->device) {
    error = "Embree: cannot create a device (error " +
            std::to_string(int(rtcGetDeviceError(nullptr))) + ")";
    return nullptr;
  }
  rtcSetDeviceMemoryMonitorFunction(backend->device, &EmbreeScene::monitor, backend.get());
  backend->scene = rtcNewScene(backend->device);
  rtcSetSceneBuildQuality(backend->scene,
                          input.high_quality ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
  for (size_t m = 0; m < input.mesh_count; ++m) {
    const EmbreeMesh& mesh = input.meshes[m];
    RTCGeometry geom = rtcNewGeometry(backend->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree's own buffers carry the padding its SIMD loads need after the last vertex.
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertex_count));
    auto* indices = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(uint32_t), mesh.triangle_count));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geom);
      error = "Embree: out of memory for a mesh of " + std::to_string(mesh.triangle_count) +
              " triangles";
      return nullptr;
    }
    std::memcpy(vertices, mesh.positions, mesh.vertex_count * 3 * sizeof(float));
    std::memcpy(indices, mesh.triangles, mesh.triangle_count * 3 * sizeof(uint32_t));
    rtcCommitGeometry(geom);
    uint32_t id = rtcAttachGeometry(backend->scene, geom);
    rtcReleaseGeometry(geom);
    if (backend->geometry_base.size() <= id) backend->geometry_base.resize(id + 1, 0);
    backend->geometry_base[id] = mesh.first_primitive;
  }
  if (input.analytic_count > 0) {
    RTCGeometry geom = rtcNewGeometry(backend->device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, unsigned(input.analytic_count));
    rtcSetGeometryUserData(geom, backend.get());
    rtcSetGeometryBoundsFunction(geom, &EmbreeScene::bounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, &EmbreeScene::intersect);
    rtcSetGeometryOccludedFunction(geom, &EmbreeScene::occluded);
    rtcCommitGeometry(geom);
    uint32_t id = rtcAttachGeometry(backend->scene, geom);
    rtcReleaseGeometry(geom);
    if (backend->geometry_base.size() <= id) backend->geometry_base.resize(id + 1, 0);
    backend->geometry_base[id] = input.first_analytic;
  }
  const int64_t before_build = backend->device_bytes;
  rtcCommitScene(backend->scene);
  backend->build_bytes = size_t(std::max<int64_t>(backend->device_bytes - before_build, 0));
  backend->packet_width =
      rtcGetDeviceProperty(backend->device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) ? 16 : 8;
  if (RTCError e = rtcGetDeviceError(backend->device); e != RTC_ERROR_NONE) {
    error = "Embree: building the scene failed (error " + std::to_string(int(e)) + ")";
    return nullptr;
  }
  return backend.release();
}

namespace {

bool closest(const EmbreeScene& backend, const Ray& ray, HitRecord& hit) {
  QueryContext context;
  rtcInitIntersectContext(&context.embree);
  context.hits = &hit;
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

bool occluded(const EmbreeScene& backend, const Ray& ray) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r;
  set_ray(r, ray);
  rtcOccluded1(backend.scene, &context, &r);
  return r.tfar < 0.0f;
}

// Rays [first, first + K) of the packet as one rtcIntersectK call.
template <int K, class RayHitK, class Fn>
void intersect_k(const EmbreeScene& backend, const RayPacket& packet, int first, HitRecord* hits,
                 Fn&& rtc_intersect) {
  alignas(64) int valid[K];
  alignas(64) RayHitK rh;
  for (int i = 0; i < K; ++i) {
    int k = first + i;
    valid[i] = k < packet.count ? -1 : 0;
    rh.ray.org_x[i] = packet.origin[0];
    rh.ray.org_y[i] = packet.origin[1];
    rh.ray.org_z[i] = packet.origin[2];
    rh.ray.dir_x[i] = k < packet.count ? packet.dir[0][k] : 0.0f;
    rh.ray.dir_y[i] = k < packet.count ? packet.dir[1][k] : 0.0f;
    rh.ray.dir_z[i] = k < packet.count ? packet.dir[2][k] : 1.0f;
    rh.ray.tnear[i] = packet.tmin;
    rh.ray.tfar[i] = packet.tmax;
    rh.ray.time[i] = 0.0f;
    rh.ray.mask[i] = 0xFFFFFFFFu;
    rh.ray.id[i] = unsigned(i);
    rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  QueryContext context;
  rtcInitIntersectContext(&context.embree);
  context.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  context.hits = hits + first;
  rtc_intersect(valid, backend.scene, &context.embree, &rh);
  for (int i = 0; i < K && first + i < packet.count; ++i) {
    if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
    HitRecord& h = hits[first + i];
    h.t = rh.ray.tfar[i];
    h.primitive = backend.geometry_base[rh.hit.geomID[i]] + rh.hit.primID[i];
    h.u = rh.hit.u[i];
    h.v = rh.hit.v[i];
  }
}

void closest_packet(const EmbreeScene& backend, const RayPacket& packet, HitRecord* hits) {
  RVR_CHECK(backend.packet_width == 8 || backend.packet_width == 16,
            "create() picks Embree's 8- or 16-wide packets: ", backend.packet_width);
  for (int i = 0; i < packet.count; ++i) hits[i] = HitRecord{};
  if (backend.packet_width == 16) {
    for (int first = 0; first < packet.count; first += 16)
      intersect_k<16, RTCRayHit16>(backend, packet, first, hits,
                                   [](const int* v, RTCScene s, RTCIntersectContext* c,
                                      RTCRayHit16* r) { rtcIntersect16(v, s, c, r); });
  } else {
    for (int first = 0; first < packet.count; first += 8)
      intersect_k<8, RTCRayHit8>(backend, packet, first, hits,
                                 [](const int* v, RTCScene s, RTCIntersectContext* c,
                                    RTCRayHit8* r) { rtcIntersect8(v, s, c, r); });
  }
}

int packet_width(const EmbreeScene& backend) {
  return backend.packet_width;
}

size_t build_bytes(const EmbreeScene& backend) {
  return backend.build_bytes;
}

const char* kernel_isa() {
  // Embree says which of its kernels it runs only in its verbose start-up report, on stdout:
  // capture it once in a temporary file.
  static const std::string isa = [] {
    std::fflush(stdout);
    FILE* capture = std::tmpfile();
    if (!capture) return std::string("unknown");
    int saved = ::dup(1);
    ::dup2(::fileno(capture), 1);
    RTCDevice device = rtcNewDevice(device_config("verbose=1").c_str());
    std::fflush(stdout);
    ::dup2(saved, 1);
    ::close(saved);
    if (device) rtcReleaseDevice(device);
    std::rewind(capture);
    std::string result = "unknown";
    char line[512];
    while (std::fgets(line, sizeof line, capture)) {
      std::string l = line;
      size_t supported = l.find("(supported)");
      size_t colon = l.find(':');
      if (l.find("Targets") == std::string::npos || supported == std::string::npos ||
          colon == std::string::npos)
        continue;
      // "Targets : SSE SSE2 ... AVX2  (supported)": the last one is the widest it runs.
      std::string targets = l.substr(colon + 1, supported - colon - 1);
      size_t end = targets.find_last_not_of(' ');
      size_t begin = targets.find_last_of(' ', end);
      result = targets.substr(begin == std::string::npos ? 0 : begin + 1, end - begin);
    }
    std::fclose(capture);
    return result;
  }();
  return isa.c_str();
}

void destroy(EmbreeScene* scene) {
  delete scene;
}

EmbreeScene* create(const EmbreeSceneInput& input, std::string& error) {
  return EmbreeScene::create(input, error);
}

}  // namespace
}  // namespace rvr

extern "C" __attribute__((visibility("default"))) const rvr_embree* rvr_embree_get() {
  static const rvr_embree table = {
      RVR_EMBREE_ABI_VERSION, &rvr::create,     &rvr::destroy,
      &rvr::closest,          &rvr::occluded,   &rvr::closest_packet,
      &rvr::packet_width,     &rvr::kernel_isa, &rvr::build_bytes,
  };
  return &table;
}
