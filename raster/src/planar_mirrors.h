// Planar mirrors the z-buffer way: what a flat mirror shows is the scene drawn again through the
// camera reflected in the mirror's plane (view · R), keeping only what lies beyond the mirror (a
// clip plane at it), and put on the pixels where the first pass saw the mirror. At each such
// pixel the reflected pass holds what the tracer's reflection ray from that point meets, so the
// two loop orders agree up to the z-buffer's sampling. A mirror seen in a reflected pass gets a
// pass of its own, one level per bounce, to the tracer's recursion limit. Both z-buffers
// (GlRasterizer, SoftRasterizer) composite their passes through this one recursion.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "draw_list_prep.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"

namespace rvr {

// A mirror object whose drawn mesh lies in one plane (a square, a disc, a flat mesh).
struct PlanarMirror {
  uint32_t object = 0;    // index in Scene::objects
  glm::dvec4 plane{0.0};  // (n, d) with |n| = 1: n · P + d = 0 on the mirror
  float mirror = 0.0f;    // the material's mirror share
};

// The mirrors of `prepared` (material mirror > 0, something drawn) that are planar, with their
// planes, in object order (the others are curved: environment_maps.h).
std::vector<PlanarMirror> planar_mirrors(const PreparedScene& prepared);

// The reflection about `plane` ((n, d), |n| = 1): P - 2 (n · P + d) n, as a matrix.
glm::dmat4 reflection_matrix(const glm::dvec4& plane);

// A view of the scene: the camera's own, or one seen through mirrors. World points are drawn at
// `reflection` · P through the pass's view-projection; `eye` is where the view looks from in the
// world (the camera's eye, or a lens point, reflected), the point shading takes V towards.
struct MirrorView {
  glm::dmat4 reflection{1.0};      // the mirrors' reflections composed (identity: the camera)
  glm::vec3 eye{0.0f};             // the eye the view shades towards
  std::optional<glm::dvec4> keep;  // world plane: only points with keep · (P, 1) >= 0 are drawn
  uint32_t hidden = kNoId;         // the mirror this view is seen in: not drawn
  int depth = 0;                   // reflections so far
};

// Draws and shades the scene through `view` (full mode, its mirrors' own shares still local),
// returning the frame: colour and object ids.
using MirrorViewPass = std::function<Expected<FrameBuffers>(const MirrorView&)>;

struct MirrorStats {
  int passes = 0;        // reflected views drawn
  int deepest = 0;       // the most reflections a drawn view holds
  uint64_t pixels = 0;   // mirror pixels given a reflection, summed over views
  uint64_t dropped = 0;  // mirror pixels at the recursion limit, whose reflection is dropped
};

// The reflections of every planar mirror seen in `fb` (drawn through `view`), composited as the
// tracer's shading equation: on the pixels whose object is mirror m, colour = (1 - m) · colour +
// m · (the view reflected in m there). A reflected view's own mirrors count only where its
// mirror is seen: a mirror it shows elsewhere gets no view. A view holding max_depth reflections
// gets no more: its mirror pixels keep (1 - m) · colour, the mirrored share dropped, as the tracer
// drops it.
Status add_planar_reflections(const std::vector<PlanarMirror>& mirrors, int max_depth,
                              const MirrorView& view, const MirrorViewPass& pass, FrameBuffers& fb,
                              MirrorStats& stats);

// The mirror stats of a render (mirror.views, mirror.depth, mirror.pixels,
// mirror.pixels_at_limit, time.mirrors) into `out`.
void record_mirror_stats(const MirrorStats& stats, double seconds, RenderOutput& out);

}  // namespace rvr
