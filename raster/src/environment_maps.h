// Curved mirrors and transparent objects the z-buffer way: a dynamic cube environment map. The
// scene is drawn six times from the centre of the object's bounds (90° square views along ±x, ±y,
// ±z, the object itself left out), and each pixel that sees the object looks the map up in the
// direction of the tracer's reflection ray (reflect(D, N)) and, for a transparent object, of its
// transmitted ray (Snell's law, total internal reflection reflected): bent at the first
// interface, and for a sphere bent again where it leaves (the second interface in closed form).
// The classic approximation's errors are built in: the map is seen from the centre, not from
// the surface point (parallax), the object does not reflect itself, a closed object other than
// a sphere bends the ray at its first interface only, and what the map shows keeps its own
// mirrors' and glass's local colour (one bounce). Both z-buffers (GlRasterizer, SoftRasterizer)
// draw the faces and composite through this one code.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "draw_list_prep.h"
#include "planar_mirrors.h"
#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr {

// An object whose mirror or transparency share a cube map answers.
struct EnvironmentMapped {
  uint32_t object = 0;        // index in Scene::objects
  glm::vec3 centre{0.0f};     // where its map is drawn from: the centre of its drawn bounds
  float radius = 0.0f;        // half its bounds' diagonal
  float reach = 0.0f;         // the distance from the centre to the farthest drawn vertex
  float mirror = 0.0f;        // the share reflected through the map (0 on a planar mirror)
  float transparency = 0.0f;  // the share transmitted through the map
  float ior = 1.0f;
  // An analytic sphere (drawn as its tessellation): its transmitted ray leaves it again where
  // the ray meets the sphere a second time, bent a second time there.
  bool sphere = false;
  glm::vec3 sphere_centre{0.0f};
  float sphere_radius = 0.0f;
};

// The objects of `prepared` with a mirror or transparency share that no planar view answers
// (`planar`), in object order. A transparent planar mirror whose ior is not 1 is left out (its
// mirror has views of its own, its transparency none) and named in `left_out`.
std::vector<EnvironmentMapped> environment_mapped(const Scene& scene, const PreparedScene& prepared,
                                                  const std::vector<PlanarMirror>& planar,
                                                  std::vector<std::string>& left_out);

// One face of a cube map: the view from `eye` along one axis, 90° square, `size` pixels a side,
// drawn without object `hidden`. Its near plane lies well inside the object (a hundredth of its
// radius: the camera's could cut away what the object stands on), its far plane beyond the
// farthest thing drawn (a reflection ray has no far plane). The frame's row 0 is the top row, as
// every frame's.
struct CubeFace {
  int face = 0;  // 0..5: +x, -x, +y, -y, +z, -z
  glm::dmat4 view{1.0}, projection{1.0};
  float near = 0.0f, far = 0.0f;
  glm::vec3 eye{0.0f};
  int size = 0;
  uint32_t hidden = kNoId;
};

// Draws and shades the scene through `face` (full mode, its mirrors and glass local), returning
// the frame: colour at every pixel.
using CubeFacePass = std::function<Expected<FrameBuffers>(const CubeFace&)>;

struct EnvironmentStats {
  int faces = 0;                // cube faces drawn
  uint64_t reflected = 0;       // pixels given a reflection from a map
  uint64_t refracted = 0;       // pixels given a transmitted colour from a map
  uint64_t total_internal = 0;  // of those, rays reflected by total internal reflection
  uint64_t dropped = 0;         // pixels at the recursion limit (--max-depth 0): shares dropped
  // Curved-mirror pixels reflected by screen-space reflections, by SsrOutcome: hit,
  // background, off screen, hidden.
  uint64_t ssr[4] = {0, 0, 0, 0};
};

// The camera's frame `fb` (drawn through the camera of `scene`, or the sample
// `options.image_sample`) with every mapped object's pixels composited as the tracer's shading
// equation: colour = (1 - mirror - transparency) · local + mirror · map(reflected direction) +
// transparency · map(transmitted direction); through a sphere the transmitted share is what the
// tracer's exit point returns, the front's local colour standing in for the back's (which no
// pass shaded). With max_depth 0 the shares are dropped, as the
// tracer drops them, and no map is drawn.
Status add_environment_maps(const Scene& scene, const RenderOptions& options,
                            const std::vector<EnvironmentMapped>& mapped, const CubeFacePass& pass,
                            FrameBuffers& fb, EnvironmentStats& stats);

// The shadow-map resolution of a cube map's faces: the map's own (a face texel and a shadow texel
// then span the same angle), never finer than the camera's shadow maps and at least 16.
// Marks the pixels of `mapped`'s objects as left out (EffectAnswer::LeftOut): with no cube map
// (--cube-map-size 0) they keep the local colour at full weight.
void mark_left_out(const std::vector<EnvironmentMapped>& mapped, FrameBuffers& fb);

int cube_face_shadow_map_size(const RenderOptions& options);

// The stats of a render's cube maps (cube_map.faces, cube_map.reflected_pixels,
// cube_map.refracted_pixels, cube_map.total_internal, time.cube_maps) into `out`.
void record_environment_stats(const EnvironmentStats& stats, double seconds, RenderOutput& out);

// What a z-buffer says of the objects a cube map answers (what the map cannot show), or leaves
// local (cube maps off: --cube-map-size 0), reflects in screen space (--zbuffer-reflection ssr),
// and of the transparent planar mirrors left out, into
// `warnings`.
void note_environment_maps(const Scene& scene, const RenderOptions& options,
                           const std::vector<EnvironmentMapped>& mapped,
                           const std::vector<std::string>& left_out,
                           std::vector<std::string>& warnings);

}  // namespace rvr
