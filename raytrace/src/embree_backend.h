// Intel Embree 3 answering TraceGeometry's queries, through the Embree plugin (embree_abi.h,
// librvr_embree.so) opened on the first Embree scene: the tracer itself does not link Embree.
#pragma once

#include <cstddef>
#include <string>

#include "rvr/core/ray.h"
#include "rvr/raytrace/trace_geometry.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

// Builds Embree's device and scene over `geometry`; null with `error` set on failure (the
// plugin cannot be loaded, or Embree fails).
EmbreeBackend* make_embree_backend(const TraceGeometry& geometry, std::string& error);
bool embree_closest(const EmbreeBackend& backend, const Ray& ray, HitRecord& hit);
bool embree_occluded(const EmbreeBackend& backend, const Ray& ray);
// A tile of primary rays through rtcIntersect8 or rtcIntersect16 (the device's native width),
// in consecutive groups of that many rays.
void embree_closest_packet(const EmbreeBackend& backend, const RayPacket& packet, HitRecord* hits);
int embree_packet_width(const EmbreeBackend& backend);
// Bytes Embree's build of the scene holds (embree_abi.h, build_bytes).
size_t embree_build_bytes(const EmbreeBackend& backend);

}  // namespace rvr
