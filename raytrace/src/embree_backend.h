// Intel Embree 3 answering TraceGeometry's queries: Embree's BVH and watertight triangle test
// for meshes, our own intersection code (as Embree user geometry) for spheres, squares and CSG.
#pragma once

#include <string>

#include "rvr/raytrace/trace_geometry.h"

namespace rvr {

// Builds Embree's device and scene over `geometry`; null with `error` set on failure.
EmbreeBackend* make_embree_backend(const TraceGeometry& geometry, std::string& error);
bool embree_closest(const EmbreeBackend& backend, const Ray& ray, HitRecord& hit);
bool embree_occluded(const EmbreeBackend& backend, const Ray& ray);

}  // namespace rvr
