// Why two renders see different things at a pixel, decided from both renderers' hits: the
// primitive each hit (its projected edges), the two view depths and how finely each renderer's
// visibility test resolves depth there (docs/cli.md, "Mismatch classes").
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rvr/core/framebuffers.h"
#include "rvr/core/scene.h"
#include "rvr/image_codec/image_io.h"

namespace rvr {

// How a renderer's visibility test stores depth, which bounds how close two surfaces may be
// and still be ordered.
enum class DepthStore {
  ViewFloat,          // view depth (or the ray parameter) in float or better: the tracers
  Window24,           // 24-bit fixed-point window depth in [0, 1], near at 0 (GL's d24)
  Window32F,          // float window depth in [0, 1], near at 0 (d32f)
  Window32FReversed,  // float window depth, near at 1 and far at 0 (reversed Z, d32f_reversed)
};
const char* to_string(DepthStore store);  // "float", "d24", "d32f", "d32f_reversed"
// The names to_string gives, and "d32f_reversed"'s alias "d32f_rev"; nullopt for anything else.
std::optional<DepthStore> parse_depth_store(const std::string& name);

// The smallest view-depth separation the store orders at view depth z, with the camera's near
// and far planes (near > 0, far > near, near <= z). See the derivation in mismatch_classes.cpp.
double depth_resolution(DepthStore store, double z, double near, double far);

enum class MismatchClass : uint8_t {
  None,            // the ids agree
  Edge,            // the pixel centre is within the edge tolerance of a hit primitive's edge
  DepthPrecision,  // both hit, the surfaces within the two depth resolutions of each other
  Occlusion,       // both hit, one surface farther than the other by more than that
  Coverage,        // a hit in one image only, away from every edge of the hit primitive
};
const char* to_string(MismatchClass c);  // "none", "edge", "depth_precision", ...
// The names to_string gives, "none" excepted; nullopt for anything else.
std::optional<MismatchClass> parse_mismatch_class(const std::string& name);

struct MismatchCounts {
  size_t edge = 0;
  size_t depth_precision = 0;
  size_t occlusion = 0;
  size_t coverage = 0;
  size_t total() const { return edge + depth_precision + occlusion + coverage; }
  size_t not_edge() const { return depth_precision + occlusion + coverage; }
  size_t of(MismatchClass c) const;
};

// Edge tolerance in pixels. A tie at an edge is a pixel centre that the two renderers put on
// opposite sides of the edge through rounding: llvmpipe snaps vertices to 1/256 pixel, which
// moves an edge by at most sqrt(2)/512 = 0.0028 pixel; a float tracer's barycentric tests err
// by a few ulps of the vertex coordinates, 1e-3 pixel or less for models within 2^10 pixels of
// the view axis. 1/128 pixel covers both with a factor of 2.8 over the snapping; it stays small
// so that on a dense mesh (triangles of about a pixel) a band of only ~7 % of the pixels lies
// within it, and a z-fight there is not excused as an edge tie.
inline constexpr double kEdgeTolerancePixels = 1.0 / 128.0;

// What classification needs beside the two frame buffers.
struct MismatchContext {
  // The scene rendered: its camera gives the pixel rays, its meshes the triangles whose ids
  // the renderers report. Null: no geometry, so every mismatch next to an object or primitive
  // boundary (3x3, either image) is an edge tie, the older, coarser rule.
  const Scene* scene = nullptr;
  DepthStore store_a = DepthStore::ViewFloat;
  DepthStore store_b = DepthStore::ViewFloat;
  double edge_tolerance_pixels = kEdgeTolerancePixels;
  // > 0 when both renderers drew and traced the round shapes (spheres, discs) as their triangle
  // forms of sphere_segments (SphereMode::Mesh): their primitive ids then index those facets.
  int sphere_segments = 0;
  // > 0 when spheres are analytic (SphereMode::Analytic): a tracer hits the sphere itself
  // while a z-buffer, which cannot draw one, draws tessellate_sphere(sphere,
  // polygon_sphere_segments), a polygon inside it. Depth metrics then tell that polygon's
  // depth differences from real disagreements (DepthOutlierCause::AnalyticSphere).
  int polygon_sphere_segments = 0;
};

// One class per pixel (None where the (object, primitive) ids agree, background counting as
// one id). Both buffers have the same size; otherwise every pixel is Coverage.
//
// Edge: an object whose primitive ids index triangles (a mesh, or a sphere's or disc's facets
// when context.sphere_segments > 0) gives the hit triangle; the pixel centre's distance to its
// nearest projected edge, in pixels, is tested against the tolerance, for the hit of either
// image. Objects drawn as one primitive (analytic spheres, planes, CSG) have no edges inside
// them; their outline stands in: a 3x3 neighbourhood holding another object or the background
// in either image.
std::vector<MismatchClass> classify_mismatches(const FrameBuffers& a, const FrameBuffers& b,
                                               const MismatchContext& context);

MismatchCounts count_classes(const std::vector<MismatchClass>& classes);

// Display-referred colours of the classes in the overlay.
inline constexpr std::array<std::array<float, 3>, 5> kMismatchClassColours = {{
    {0.0f, 0.0f, 0.0f},   // none: not drawn (grey of image a)
    {0.3f, 0.55f, 1.0f},  // edge: blue
    {1.0f, 0.85f, 0.0f},  // depth_precision: yellow
    {1.0f, 0.1f, 0.1f},   // occlusion: red
    {1.0f, 0.2f, 1.0f},   // coverage: magenta
}};

// Each mismatched pixel in its class's colour over a grey version of a's colour.
Image mismatch_class_image(const FrameBuffers& a, const std::vector<MismatchClass>& classes);

}  // namespace rvr
