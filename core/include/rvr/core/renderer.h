// The interface every renderer implements; tests run one conformance suite over all of them.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/isa.h"
#include "rvr/core/progress.h"
#include "rvr/core/scene.h"
#include "rvr/core/texture.h"

namespace rvr {

enum class RenderMode { Visibility, Local, Full };
enum class SphereMode { Analytic, Mesh };
// Bvh: the wide SIMD BVH (default); Bvh2: the binary BVH traversed one box at a time (the
// chapter's early rejection in its plainest form); None: every object for every ray; Embree:
// Intel Embree 3 answers the queries.
enum class AccelKind { Bvh, Bvh2, None, Embree };
enum class TriangleTest { MollerTrumbore, Chapter };
// How a rasterizer's z-buffer stores depth (docs/cli.md, --depth-format). D24: window-space z
// (0 at near, 1 at far, hyperbolic in view depth) as a 24-bit unsigned normalized integer;
// D32F: the same z as a 32-bit float; D32FReversed: z reversed (1 at near, 0 at far, float's
// dense exponents near 0 where the hyperbola is flattest), tested with "greater".
enum class DepthFormat { D24, D32F, D32FReversed };
// How a GL z-buffer takes several samples per pixel (docs/cli.md, --supersampling).
// Accumulation: one pass per sample of the tracer's own set (its positions in the pixel, its
// lens points), averaged; Msaa: one multisampled pass at the GL's own sample positions, no lens.
enum class Supersampling { Accumulation, Msaa };
// How a z-buffer renders depth of field (docs/cli.md, --zbuffer-dof). Accumulation: each sample
// pass through its lens point; Blur: pinhole passes, then the image blurred by each pixel's
// circle of confusion (a post-process).
enum class ZBufferDof { Accumulation, Blur };
// How a z-buffer renders curved mirrors (docs/cli.md, --zbuffer-reflection). CubeMap: a cube
// environment map per mirror; Ssr: screen-space reflections over the camera's own frame.
enum class ZBufferReflection { CubeMap, Ssr };

const char* to_string(RenderMode mode);
const char* to_string(AccelKind accel);     // bvh, bvh2, none, embree
const char* to_string(DepthFormat format);  // d24, d32f, d32f_reversed
std::optional<DepthFormat> parse_depth_format(const std::string& name);

struct RenderOptions {
  RenderMode mode = RenderMode::Local;
  SphereMode spheres = SphereMode::Analytic;  // tracers: analytic or the raster's tessellation
  int sphere_segments = 64;                   // tessellation: longitudes (rings = segments/2)
  int threads = 0;                            // 0 = every core
  int max_depth = 5;
  uint64_t seed = 0;
  AccelKind accel = AccelKind::Bvh;
  TriangleTest triangle_test = TriangleTest::MollerTrumbore;
  // SIMD kernels to run; unset: selected_isa() (RVR_ISA, or the best the CPU has).
  std::optional<Isa> isa;
  // Rasterizers, full mode: shadow maps (a cube map per point light, one map per area-light
  // sample point). Resolution in texels per side; bias in units of view depth of the map,
  // added to the stored depth before comparing; percentage-closer filtering over 3x3 texels.
  int shadow_map_size = 1024;
  float shadow_bias = 0.01f;
  bool shadow_pcf = false;
  // Rasterizers: the z-buffer's depth format; only which surface wins a pixel changes, the
  // depth AOV stays the linear view depth. Unset: the most precise the renderer has (raster:
  // d32f_reversed when the GL offers ARB_clip_control, else d32f; softraster: view depth in
  // double precision, finer than any of the formats). The tracers ignore it.
  std::optional<DepthFormat> depth_format;
  // raster: how several samples per pixel are taken (softraster and the hybrids always take the
  // tracer's samples, one pass each).
  Supersampling supersampling = Supersampling::Accumulation;
  // Z-buffers in full mode with an aperture: how depth of field is rendered.
  ZBufferDof zbuffer_dof = ZBufferDof::Accumulation;
  // Z-buffers in full mode: texels per side of the cube environment map drawn for each curved
  // mirror and transparent object (0: none, their local colour only).
  int cube_map_size = 256;
  // Z-buffers in full mode: how curved mirrors are reflected (flat ones always by views).
  ZBufferReflection zbuffer_reflection = ZBufferReflection::CubeMap;
  // Tracers: how a ray chooses a texture's level of detail (the z-buffers take theirs from
  // screen-space derivatives; the hybrids' primary hits from their z-buffer's).
  TextureLod texture_lod = TextureLod::Cones;
  // Z-buffers in visibility mode: also write FrameBuffers::lod (their level of detail of each
  // textured pixel), which the hybrids' primary hits then sample at.
  bool visibility_lod = false;
  // softraster in visibility mode: write object_id and primitive_id only (and lod with
  // visibility_lod), leaving depth, colour, normal and cost empty: the hybrids' z-buffer pass,
  // whose tracer rebuilds every hit from the ids. The ids are its depth target's, handed over
  // rather than copied, so primitive_id is defined only where an object was drawn, and there is
  // the drawn triangle's index also for an object that does not name its triangles (where the
  // full visibility buffer says 0). raster reads its buffers back as before.
  bool visibility_ids_only = false;
  // Z-buffers: scene objects (indices into Scene::objects) left out of every view they draw; the
  // others keep their ids. The hybrids leave out the shapes their tracer intersects wherever
  // those may appear (TraceGeometry::closest_approximated), which the z-buffer would only draw
  // as polygons inside them.
  std::vector<uint32_t> zbuffer_left_out;
  // softraster: hierarchical z (each 8x8 block's farthest depth rejects triangles behind it).
  bool hiz = true;
  // Cost AOV: false: the caller does not read the cost AOV, which is then 0 everywhere (the
  // z-buffers skip their fragment-count pass).
  bool cost_aov = true;
  // Rasterizers: draw what this one sample of every pixel sees (its place in the pixel, its lens
  // point) instead of the pixel centres through a pinhole: one pass of an accumulation buffer.
  // The hybrid sets it for its visibility passes; unset, nothing changes.
  std::optional<ImageSample> image_sample;
  // Where to report work done (per tile or chunk, never per ray); null: nobody is watching.
  // Reporting must change neither the image nor the order of work.
  ProgressSink* progress = nullptr;
};

struct RenderOutput {
  FrameBuffers buffers;
  // Counters and phase times (seconds), e.g. "time.build", "rays.primary", "bvh.nodes_visited":
  // each name declared once in stats.h (what it measures, its kind and unit).
  std::map<std::string, double> stats;
  // What the renderer could not do for this scene (e.g. "csg objects skipped: 1").
  std::vector<std::string> warnings;
  // Facts that are words, not numbers, e.g. "kernel": "avx2".
  std::map<std::string, std::string> info;
};

class Renderer {
 public:
  virtual ~Renderer() = default;
  virtual std::string name() const = 0;
  virtual Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options) = 0;
};

}  // namespace rvr
