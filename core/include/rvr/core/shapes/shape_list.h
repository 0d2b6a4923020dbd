// The analytic shapes, one line each: RVR_ANALYTIC_SHAPES(X) expands X(Type, Enumerator, member)
// for every shape, Type its type (shapes/*.h), Enumerator its ObjectType and member its field in
// Object. The object kinds that are not one shape (triangle meshes, CSG trees) are written out
// beside the list where it is expanded: the ObjectType enumeration and Object (scene.h),
// visit_shape and TracedShape (shapes.h), the scene reader and writer (scene_io/). Adding a
// shape is adding its line here (docs/design.md, "Adding a primitive").
#pragma once

#include "rvr/core/shapes/disc.h"    // IWYU pragma: export
#include "rvr/core/shapes/sphere.h"  // IWYU pragma: export
#include "rvr/core/shapes/square.h"  // IWYU pragma: export

// clang-format off
#define RVR_ANALYTIC_SHAPES(X) \
  X(Sphere, Sphere, sphere)    \
  X(Square, Plane, plane)      \
  X(Disc, Disc, disc)
// clang-format on
