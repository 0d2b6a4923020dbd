// softraster's deferred shading pass: after the z-buffer pass, every pixel of the frame buffers
// is written once: the background where nothing was drawn, else depth, ids, the shading normal
// and the colour, the visible pixels shaded a batch at a time by a SIMD shading kernel
// (rvr/core/shade_kernel.h). Visibility mode writes depth, ids and cost only
// (write_visibility), with the same code for those buffers.
#pragma once

#include <tbb/task_arena.h>

#include <glm/glm.hpp>
#include <vector>

#include "rvr/core/framebuffers.h"
#include "rvr/core/progress.h"
#include "rvr/core/scene.h"
#include "rvr/core/shade_kernel.h"
#include "soft/draw_triangles.h"
#include "soft/surface_texture.h"
#include "soft/tile_raster.h"

namespace rvr::soft {

enum class ShadedColour {
  Base,   // emission + ambient * diffuse (the lights are added later, with shadows)
  Local,  // base plus every light sample, unshadowed
};

struct DeferredShading {
  glm::vec3 eye;
  glm::vec3 ambient;
  glm::vec3 background;
  ShadedColour colour = ShadedColour::Local;
  const std::vector<LightSample>* samples = nullptr;  // Local: the light samples, in order
  bool cost = true;  // false: the cost buffer is 0 everywhere (RenderOptions::cost_aov)
  // Not null when some object varies in colour: those pixels get their own material (diffuse =
  // the base colour there), and the lod buffer is written when some object is textured.
  const SurfaceColours* surfaces = nullptr;
};

// Sizes fb to the target and writes every pixel of every buffer.
void shade_pixels(const DrawList& list, const DepthTarget& target, const DeferredShading& settings,
                  const ShadeKernels& kernels, tbb::task_arena& arena, ProgressSink* progress,
                  FrameBuffers& fb);

// Visibility mode: sizes fb to the target and writes every pixel of every buffer without
// shading: depth, object and primitive id and cost (0 everywhere when !cost) as shade_pixels
// writes them, colour the background, normal 0.
// `surfaces` not null and some object textured: fb.lod too (the hybrids' primary hits).
void write_visibility(const DrawList& list, const DepthTarget& target, const glm::vec3& background,
                      bool cost, const SurfaceColours* surfaces, tbb::task_arena& arena,
                      ProgressSink* progress, FrameBuffers& fb);

// Visibility mode, ids only (RenderOptions::visibility_ids_only): fb sized to the target with
// the target's object and primitive ids, handed over rather than copied (DepthTarget::give_ids),
// and lod as write_visibility writes it; no other buffer. The primitive ids are the target's:
// the triangle's where an object was drawn (also for an object that does not name its
// triangles), unset where none was.
void give_visibility_ids(const DrawList& list, DepthTarget& target, const SurfaceColours* surfaces,
                         tbb::task_arena& arena, ProgressSink* progress, FrameBuffers& fb);

}  // namespace rvr::soft
