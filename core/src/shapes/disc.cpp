#include "rvr/core/shapes/disc.h"

#include <stddef.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "rvr/core/check.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/tessellate.h"

namespace rvr {

namespace {

int fan_segments(int segments) {
  return std::max(segments, 3);
}

}  // namespace

TriangleMesh tessellate_disc(const Disc& disc, int segments) {
  segments = fan_segments(segments);
  const auto [u, v] = plane_axes(disc.normal);
  const double pi = 3.141592653589793;
  const float corner = float(double(disc.radius) / std::cos(pi / double(segments)));
  TriangleMesh mesh;
  mesh.positions.push_back(disc.center);
  for (int k = 0; k < segments; ++k) {
    const double phi = 2.0 * pi * double(k) / double(segments);
    const float c = float(std::cos(phi)), s = float(std::sin(phi));
    mesh.positions.push_back(disc.center + corner * (c * u + s * v));
  }
  // u x v = n: the angle grows counter-clockwise seen from the normal's side.
  for (int k = 0; k < segments; ++k) {
    mesh.triangles.push_back({0u, uint32_t(1 + k), uint32_t(1 + (k + 1) % segments)});
  }
  RVR_CHECK(
      mesh.triangles.size() == size_t(segments) && mesh.positions.size() == size_t(segments) + 1,
      "a disc of ", segments, " segments is ", segments, " triangles");
  return mesh;
}

uint64_t Disc::triangle_count(const TessellationOptions& options) const {
  return uint64_t(fan_segments(options.sphere_segments));
}

TriangleForm Disc::triangle_form(const TessellationOptions& options) const {
  TriangleForm form;
  form.made = std::make_unique<const TriangleMesh>(tessellate_disc(*this, options.sphere_segments));
  form.mesh = form.made.get();
  form.names_triangles = !traced_analytically(options);
  return form;
}

}  // namespace rvr
