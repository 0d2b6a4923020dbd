// The analytic shapes' geometry in one place: their triangle forms (the z-buffer draws these, and
// the tracer traces them with --spheres mesh, so both loop orders can be compared on identical
// geometry), how many triangles those are (the resource estimate) and the points that bound them
// (camera framing).
#pragma once

#include <stddef.h>

#include <array>
#include <cstdint>
#include <glm/glm.hpp>

#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/square.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

// Two unit axes (u, v) spanning a plane with unit normal n, u x v = n. Both renderers use
// these for the square's edges.
std::array<glm::vec3, 2> plane_axes(const glm::vec3& n);

// UV sphere: `segments` longitudes (>= 3), segments/2 rings (>= 2); vertices on the sphere,
// smooth radial normals, counter-clockwise seen from outside.
TriangleMesh tessellate_sphere(const Sphere& sphere, int segments);

// The square as two triangles, counter-clockwise seen from the side the normal points to,
// flat (no vertex normals).
TriangleMesh tessellate_plane(const Square& plane);

// How many triangles tessellate_sphere makes with `segments` longitudes.
uint64_t sphere_triangle_count(int segments);

// The square's four corners; tessellate_plane's vertices, in its order.
std::array<glm::vec3, 4> plane_corners(const Square& plane);

// How many triangles tessellate_plane makes.
inline constexpr uint64_t kPlaneTriangleCount = 2;

// Segments for a sphere of about `triangles` triangles.
int sphere_segments_for_triangles(size_t triangles);

}  // namespace rvr
