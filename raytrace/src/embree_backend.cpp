#include "embree_backend.h"

#include <embree3/rtcore.h>  // RTC_VERSION_STRING only: Embree is not linked here

#include <cstdint>
#include <memory>
#include <vector>

#include "embree_abi.h"
#include "rvr/core/expected.h"
#include "rvr/core/plugin.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/ray_tracer.h"

namespace rvr {
namespace {

// The plugin's table, opened once per process on first use.
const Expected<const rvr_embree*>& embree_api() {
  static const Expected<const rvr_embree*> api = open_plugin_table<rvr_embree>(
      "librvr_embree.so", "rvr_embree_get", RVR_EMBREE_ABI_VERSION, "the Embree plugin");
  return api;
}

}  // namespace

struct EmbreeBackend {
  const rvr_embree* api = nullptr;
  EmbreeScene* scene = nullptr;

  EmbreeBackend() = default;
  EmbreeBackend(const EmbreeBackend&) = delete;
  EmbreeBackend& operator=(const EmbreeBackend&) = delete;
  ~EmbreeBackend() {
    if (scene) api->destroy(scene);
  }

  // The analytic shapes' callbacks: the tracer's own bounds and intersection code.
  static Aabb bounds(const void* user, uint32_t index) {
    const auto* g = static_cast<const TraceGeometry*>(user);
    return TraceGeometry::analytic_bounds(g->analytic_[index]);
  }
  static bool hit(const void* user, uint32_t index, const Ray& ray, HitRecord& hit) {
    const auto* g = static_cast<const TraceGeometry*>(user);
    return g->hit_analytic(g->analytic_[index], ray, ray.tmax, hit);
  }

  static EmbreeBackend* create(const TraceGeometry& g, std::string& error) {
    const Expected<const rvr_embree*>& api = embree_api();
    if (!api) {
      error = api.error().message;
      return nullptr;
    }
    std::vector<EmbreeMesh> meshes;
    for (size_t object = 0; object < g.object_mesh_.size(); ++object) {
      const TriangleMesh* mesh = g.object_mesh_[object];
      if (!mesh || mesh->triangles.empty()) continue;
      meshes.push_back({mesh->positions.data(), mesh->positions.size(), mesh->triangles.data(),
                        mesh->triangles.size(), g.object_first_triangle_[object]});
    }
    EmbreeSceneInput input;
    input.meshes = meshes.data();
    input.mesh_count = meshes.size();
    input.analytic_count = g.analytic_.size();
    input.first_analytic = uint32_t(g.triangles_.size());
    input.high_quality = g.embree_quality_ == EmbreeQuality::High;
    input.user = &g;
    input.analytic_bounds = &EmbreeBackend::bounds;
    input.hit_analytic = &EmbreeBackend::hit;
    auto backend = std::make_unique<EmbreeBackend>();
    backend->api = *api;
    backend->scene = backend->api->create(input, error);
    return backend->scene ? backend.release() : nullptr;
  }
};

void EmbreeBackendDeleter::operator()(EmbreeBackend* backend) const {
  delete backend;
}

EmbreeBackend* make_embree_backend(const TraceGeometry& geometry, std::string& error) {
  return EmbreeBackend::create(geometry, error);
}

bool embree_closest(const EmbreeBackend& backend, const Ray& ray, HitRecord& hit) {
  return backend.api->closest(*backend.scene, ray, hit);
}

bool embree_occluded(const EmbreeBackend& backend, const Ray& ray) {
  return backend.api->occluded(*backend.scene, ray);
}

void embree_closest_packet(const EmbreeBackend& backend, const RayPacket& packet, HitRecord* hits) {
  backend.api->closest_packet(*backend.scene, packet, hits);
}

int embree_packet_width(const EmbreeBackend& backend) {
  return backend.api->packet_width(*backend.scene);
}

size_t embree_build_bytes(const EmbreeBackend& backend) {
  return backend.api->build_bytes(*backend.scene);
}

std::string embree_kernel_isa() {
  const Expected<const rvr_embree*>& api = embree_api();
  return api ? (*api)->kernel_isa() : "unknown";
}

std::string embree_version() {
  return RTC_VERSION_STRING;
}

}  // namespace rvr
