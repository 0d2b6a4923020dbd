// Planar mirrors the z-buffer way: what a flat mirror shows is the scene drawn again through the
// camera reflected in the mirror's plane (view · R), keeping only what lies beyond the mirror (a
// clip plane at it), and put on the pixels where the first pass saw the mirror. At each such
// pixel the reflected pass holds what the tracer's reflection ray from that point meets, so the
// two loop orders agree up to the z-buffer's sampling. A mirror seen in a reflected pass gets a
// pass of its own, one level per bounce, to the tracer's recursion limit. A flat transparent
// layer with ior 1 (a pane whose transmitted ray goes straight on) is the same recursion without
// the reflection: the view drawn again without the layer holds what lies behind it, and the over
// operator puts the layer on it, back to front, as the tracer's transmitted ray does. Both
// z-buffers (GlRasterizer, SoftRasterizer) composite their passes through this one recursion.
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
#include "rvr/core/scene.h"

namespace rvr {

// A mirror or an ior-1 transparent layer whose drawn mesh lies in one plane (a square, a disc, a
// flat mesh).
struct PlanarMirror {
  uint32_t object = 0;        // index in Scene::objects
  glm::dvec4 plane{0.0};      // (n, d) with |n| = 1: n · P + d = 0 on the mirror
  float mirror = 0.0f;        // the material's mirror share
  float transparency = 0.0f;  // its transparency share when ior is 1 (the over operator), else 0
};

// The objects of `prepared` that are planar (something drawn, all in one plane) and either
// mirrors (material mirror > 0) or transparent with ior 1, with their planes, in object order.
// Curved mirrors and other transparent objects are environment_maps.h's.
std::vector<PlanarMirror> planar_mirrors(const PreparedScene& prepared);

// Whether a material's transparency is the over operator: its transmitted ray goes straight on.
bool transmits_straight(const Material& material);

// The reflection about `plane` ((n, d), |n| = 1): P - 2 (n · P + d) n, as a matrix.
glm::dmat4 reflection_matrix(const glm::dvec4& plane);

// A view of the scene: the camera's own, or one seen through mirrors and transparent layers.
// World points are drawn at `reflection` · P through the pass's view-projection; `eye` is where
// the view looks from in the world (the camera's eye, or a lens point, reflected), the point
// shading takes V towards.
struct MirrorView {
  glm::dmat4 reflection{1.0};      // the mirrors' reflections composed (identity: the camera)
  glm::vec3 eye{0.0f};             // the eye the view shades towards
  std::optional<glm::dvec4> keep;  // world plane: only points with keep · (P, 1) >= 0 are drawn
  // Not drawn: the mirror this view is seen in, and the layers it is seen through.
  std::vector<uint32_t> hidden;
  int depth = 0;  // reflections and transmissions so far
};

// Draws and shades the scene through `view` (full mode, its mirrors' own shares still local),
// returning the frame: colour and object ids.
using MirrorViewPass = std::function<Expected<FrameBuffers>(const MirrorView&)>;

struct MirrorStats {
  int passes = 0;        // reflected views drawn
  int deepest = 0;       // the most reflections and transmissions a drawn view holds
  uint64_t pixels = 0;   // mirror pixels given a reflection, summed over views
  uint64_t dropped = 0;  // mirror and layer pixels at the recursion limit, their shares dropped
  int layer_passes = 0;  // views drawn behind transparent layers
  uint64_t layer_pixels = 0;  // layer pixels given what lies behind them, summed over views
};

// The reflections of every planar mirror and what lies behind every transparent layer seen in
// `fb` (drawn through `view`), composited as the tracer's shading equation: on the pixels whose
// object has mirror share m and layer share t, colour = (1 - m - t) · colour + m · (the view
// reflected in it there) + t · (the view without it there). A child view's own mirrors and
// layers count only where its parent sees its object: one seen elsewhere gets no view. A view
// holding max_depth reflections and transmissions gets no more: its pixels keep
// (1 - m - t) · colour, the shares dropped, as the tracer drops them.
Status add_planar_reflections(const std::vector<PlanarMirror>& mirrors, int max_depth,
                              const MirrorView& view, const MirrorViewPass& pass, FrameBuffers& fb,
                              MirrorStats& stats);

// The mirror stats of a render (mirror.views, mirror.depth, mirror.pixels,
// mirror.pixels_at_limit, time.mirrors and, when some layer was seen, layer.views and
// layer.pixels) into `out`.
void record_mirror_stats(const MirrorStats& stats, double seconds, RenderOutput& out);

}  // namespace rvr
