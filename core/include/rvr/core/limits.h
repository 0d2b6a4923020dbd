// Resource limits, checked after a scene is loaded and before a renderer allocates anything:
// a mistyped size or sample count is a clear error (exit 2), not an hour of work or an
// out-of-memory kill. Each limit has a default and a CLI flag to raise it.
#pragma once

#include <cstdint>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr {

struct Limits {
  // Pixels x samples per pixel (--max-samples): 2^30, a 4K image at 128 samples.
  uint64_t max_samples = uint64_t(1) << 30;
  // Triangles drawn or traced, spheres, planes and discs tessellated included (--max-triangles).
  uint64_t max_triangles = 50'000'000;
  // Estimated peak memory in bytes (--max-memory-mb); 0 = three quarters of physical memory.
  uint64_t max_memory_bytes = 0;
};

// What a render of `scene` with `options` will need, by the same counts the renderers use.
struct ResourceEstimate {
  uint64_t samples = 0;
  uint64_t triangles = 0;
  uint64_t memory_bytes = 0;
};
ResourceEstimate estimate_resources(const Scene& scene, const RenderOptions& options);

// Three quarters of the machine's physical memory (the default memory limit).
uint64_t default_memory_limit();

// Bad input naming scene.source and the JSON path ("image", "objects") when a limit is passed.
Status check_limits(const Scene& scene, const RenderOptions& options, const Limits& limits);

}  // namespace rvr
