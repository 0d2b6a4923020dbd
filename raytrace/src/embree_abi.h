// The interface of the Embree plugin, librvr_embree.so (embree_plugin.cpp): Intel Embree 3
// answering TraceGeometry's queries. embree_backend.cpp opens it on first use, so that only a
// run of the embree renderer loads Embree (docs/design.md, "Start-up"). Both sides are built
// together from this header; the version refuses a plugin of another build.
#pragma once

#include <stddef.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <string>

#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/intersect.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh_layout.h"

#define RVR_EMBREE_ABI_VERSION 2

namespace rvr {

// A mesh as Embree gets it: world-space positions and triangles, and the unified primitive
// index of its triangle 0 (TraceGeometry's numbering, which hits report).
struct EmbreeMesh {
  const glm::vec3* positions = nullptr;
  size_t vertex_count = 0;
  const glm::uvec3* triangles = nullptr;
  size_t triangle_count = 0;
  uint32_t first_primitive = 0;
};

// What Embree builds its scene over: the meshes, and the analytic shapes (spheres, squares,
// CSG) as user geometry, bounded and intersected by the tracer's own code through the
// callbacks (index: 0 .. analytic_count - 1; hits carry primitive first_analytic + index).
struct EmbreeSceneInput {
  const EmbreeMesh* meshes = nullptr;
  size_t mesh_count = 0;
  size_t analytic_count = 0;
  uint32_t first_analytic = 0;
  bool high_quality = true;    // RTC_BUILD_QUALITY_HIGH, else MEDIUM (EmbreeQuality)
  const void* user = nullptr;  // passed back to the callbacks
  Aabb (*analytic_bounds)(const void* user, uint32_t index) = nullptr;
  // The nearest hit of shape `index` along `ray` before ray.tmax; t and CSG data in `hit`.
  bool (*hit_analytic)(const void* user, uint32_t index, const Ray& ray, HitRecord& hit) = nullptr;
};

struct EmbreeScene;  // the plugin's device and scene

}  // namespace rvr

extern "C" {

struct rvr_embree {
  int abi_version;  // RVR_EMBREE_ABI_VERSION
  // Builds Embree's device and scene over `input` (which need not outlive the call; `user`
  // must outlive the scene); null with `error` set on failure.
  rvr::EmbreeScene* (*create)(const rvr::EmbreeSceneInput& input, std::string& error);
  void (*destroy)(rvr::EmbreeScene* scene);
  bool (*closest)(const rvr::EmbreeScene& scene, const rvr::Ray& ray, rvr::HitRecord& hit);
  bool (*occluded)(const rvr::EmbreeScene& scene, const rvr::Ray& ray);
  // A tile of primary rays through rtcIntersect8 or rtcIntersect16 (the device's native
  // width), in consecutive groups of that many rays.
  void (*closest_packet)(const rvr::EmbreeScene& scene, const rvr::RayPacket& packet,
                         rvr::HitRecord* hits);
  int (*packet_width)(const rvr::EmbreeScene& scene);
  // The widest of Embree's kernels it runs on this CPU, e.g. "AVX2".
  const char* (*kernel_isa)();
  // Bytes the scene's build added to the device and kept (its BVH and the triangle data of its
  // leaves), as Embree's memory monitor reports them; the geometry buffers are not counted.
  size_t (*build_bytes)(const rvr::EmbreeScene& scene);
};

// The table; the plugin's one exported symbol.
const struct rvr_embree* rvr_embree_get(void);
}
