#include "rvr/core/limits.h"

#include <unistd.h>

#include <algorithm>
#include <string>
#include <vector>

#include "rvr/core/shapes.h"
#include "rvr/core/shapes/shape_geometry.h"

namespace rvr {
namespace {

// Bytes per pixel over a frame's life: the frame buffers (colour, normal 12 B each; depth,
// cost 4 B; object and primitive id 4 B each), the colour image written out (12 B) and the
// GL read-back or the report images (about as much again).
constexpr uint64_t kBytesPerPixel = 96;
// Bytes per triangle: the mesh (shared vertices, normals, indices), the GL vertex buffer (3
// unshared vertices with normal and ids) and the tracer's BVH and leaf-ordered triangles.
constexpr uint64_t kBytesPerTriangle = 260;

}  // namespace

ResourceEstimate estimate_resources(const Scene& scene, const RenderOptions& options) {
  ResourceEstimate e;
  uint64_t pixels =
      uint64_t(std::max(0, scene.image.width)) * uint64_t(std::max(0, scene.image.height));
  e.samples = pixels * uint64_t(std::max(1, scene.image.samples_per_pixel));
  // The z-buffers draw the triangle form whatever the tracers do.
  const TessellationOptions tessellation{options.sphere_segments, false};
  for (const Object& o : scene.objects)
    e.triangles +=
        visit_shape(o, [&](const auto& shape) { return shape.triangle_count(tessellation); });
  e.memory_bytes = pixels * kBytesPerPixel + e.triangles * kBytesPerTriangle;
  return e;
}

uint64_t default_memory_limit() {
  long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return uint64_t(8) << 30;
  return uint64_t(pages) * uint64_t(page) / 4 * 3;
}

Status check_limits(const Scene& scene, const RenderOptions& options, const Limits& limits) {
  ResourceEstimate e = estimate_resources(scene, options);
  const std::string& file = scene.source;
  if (e.samples > limits.max_samples)
    return bad_input(file + ": image: " + std::to_string(scene.image.width) + "x" +
                     std::to_string(scene.image.height) + " pixels x " +
                     std::to_string(scene.image.samples_per_pixel) +
                     " samples = " + std::to_string(e.samples) + " samples, over the limit of " +
                     std::to_string(limits.max_samples) + " (raise it with --max-samples)");
  if (e.triangles > limits.max_triangles)
    return bad_input(file + ": objects: " + std::to_string(e.triangles) +
                     " triangles (spheres, planes and discs tessellated), over the limit of " +
                     std::to_string(limits.max_triangles) + " (raise it with --max-triangles)");
  uint64_t max_memory = limits.max_memory_bytes ? limits.max_memory_bytes : default_memory_limit();
  if (e.memory_bytes > max_memory)
    return bad_input(file + ": image, objects: about " + std::to_string(e.memory_bytes >> 20) +
                     " MiB needed (" +
                     std::to_string(e.samples / std::max(1, scene.image.samples_per_pixel)) +
                     " pixels, " + std::to_string(e.triangles) + " triangles), over the limit of " +
                     std::to_string(max_memory >> 20) + " MiB (raise it with --max-memory-mb)");
  return ok_status();
}

}  // namespace rvr
