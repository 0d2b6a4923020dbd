#include "rvr/core/stats.h"

#include <array>
#include <span>
#include <string>
#include <string_view>

namespace rvr {
namespace {

constexpr StatKind kCount = StatKind::Count;
constexpr StatKind kSeconds = StatKind::Seconds;
constexpr StatKind kRatio = StatKind::Ratio;

// The one list of stats. The renderers' words: "z-buffers" are raster and softraster, "tracers"
// raytrace (and its variants) and embree, "hybrids" hybrid_gl and hybrid_soft.
constexpr std::array kStats = {
    // Work of the triangle-major loop.
    StatDeclaration{"triangles.submitted", kCount, "triangles", "z-buffers",
                    "triangles transformed, projected and tested against the view"},
    StatDeclaration{"triangles.setup", kCount, "triangles", "softraster",
                    "triangles set up (edge functions, bounding box) and binned to tiles: those "
                    "left after culling with a pixel centre in their bounds"},
    StatDeclaration{"triangles.clipped", kCount, "triangles", "softraster",
                    "triangles clipped against the near plane or the guard band"},
    StatDeclaration{"fragments.generated", kCount, "fragments", "z-buffers",
                    "pixels whose coverage and depth were tested (raster: counted by the "
                    "fragment-count pass, absent without the cost AOV)"},
    StatDeclaration{"fragments.passed", kCount, "fragments", "raster",
                    "fragments that passed the depth test and were written"},
    StatDeclaration{"fragments.shaded", kCount, "fragments", "softraster",
                    "visible pixels shaded, once each (deferred shading; 0 in visibility mode)"},
    StatDeclaration{"pixels.covered", kCount, "pixels", "z-buffers",
                    "pixels a surface covers at the end (what is seen)"},
    StatDeclaration{"overdraw", kRatio, "fragments per pixel", "z-buffers",
                    "fragments.generated / pixels.covered: how often a seen pixel was tested"},
    StatDeclaration{"blocks.full", kCount, "blocks", "softraster",
                    "8×8 blocks a triangle covers whole, drawn without edge tests"},
    StatDeclaration{"hiz.blocks_rejected", kCount, "blocks", "softraster",
                    "8×8 blocks skipped whole by hierarchical z, one test each"},
    StatDeclaration{"hiz.triangles_rejected", kCount, "triangles", "softraster",
                    "triangles hierarchical z skipped in a whole tile at once"},
    StatDeclaration{"memory.raster_bytes", kCount, "bytes", "softraster",
                    "the depth target and the largest chunk of set-up triangles held at once"},
    StatDeclaration{"zbuffer.depth_bits", kCount, "bits", "raster",
                    "the depth buffer's bits per pixel (24 or 32)"},
    StatDeclaration{"dof.blur_radius", kRatio, "pixels", "z-buffers",
                    "the widest circle of confusion of a depth-of-field blur, before clamping "
                    "to 32 pixels (--zbuffer-dof blur)"},
    StatDeclaration{"zbuffer.accumulation_passes", kCount, "passes", "z-buffers",
                    "sample passes of an accumulation buffer (samples_per_pixel > 1), each "
                    "drawn and shaded whole, after the centre pass that gives the AOVs"},
    // Curved mirrors and glass drawn by the z-buffers (full mode): a cube map per object seen.
    StatDeclaration{"cube_map.faces", kCount, "faces", "z-buffers",
                    "cube-map faces drawn for curved mirrors and transparent objects: six per "
                    "object seen (full mode)"},
    StatDeclaration{"cube_map.reflected_pixels", kCount, "pixels", "z-buffers",
                    "pixels given a reflection looked up in a cube map"},
    StatDeclaration{"cube_map.refracted_pixels", kCount, "pixels", "z-buffers",
                    "pixels given a transmitted colour looked up in a cube map"},
    StatDeclaration{"cube_map.total_internal", kCount, "pixels", "z-buffers",
                    "totally internally reflected rays among the refracted pixels' (at either "
                    "interface; looked up in the reflected direction)"},
    // CSG solids drawn by the z-buffers: two depth passes per leaf, combined per pixel.
    StatDeclaration{"csg.objects", kCount, "objects", "z-buffers",
                    "CSG objects drawn, leaf by leaf"},
    StatDeclaration{"csg.leaf_passes", kCount, "passes", "z-buffers",
                    "depth passes over the CSG leaves' tessellations: two per leaf and view (the "
                    "triangles facing the eye, then those facing away); `raster` counts every "
                    "view it drew (camera, mirror views, cube faces, shadow-cube faces)"},
    StatDeclaration{"csg.fragments", kCount, "fragments", "softraster",
                    "fragments the CSG leaf passes generated"},
    StatDeclaration{"csg.pixels", kCount, "pixels", "z-buffers",
                    "pixels where a CSG surface was nearer than the rest of the frame"},
    StatDeclaration{"ssr.hits", kCount, "pixels", "z-buffers",
                    "curved-mirror pixels whose screen-space reflection ray meets a surface the "
                    "frame holds (--zbuffer-reflection ssr)"},
    StatDeclaration{"ssr.background", kCount, "pixels", "z-buffers",
                    "curved-mirror pixels whose screen-space ray stays in front of everything to "
                    "the end of the scene: nothing met"},
    StatDeclaration{"ssr.off_screen", kCount, "pixels", "z-buffers",
                    "curved-mirror pixels whose screen-space ray leaves the view (or turns "
                    "behind the camera) first: a miss"},
    StatDeclaration{"ssr.hidden", kCount, "pixels", "z-buffers",
                    "curved-mirror pixels whose screen-space ray passes behind a surface first: "
                    "what it meets is hidden, a miss"},
    // Planar mirrors drawn by the z-buffers (full mode): a reflected view per mirror seen.
    StatDeclaration{"mirror.views", kCount, "views", "z-buffers",
                    "reflected views drawn for planar mirrors: one per mirror seen, per level of "
                    "reflection (full mode)"},
    StatDeclaration{"mirror.depth", kCount, "reflections", "z-buffers",
                    "the most reflections one drawn view holds (at most --max-depth)"},
    StatDeclaration{"mirror.pixels", kCount, "pixels", "z-buffers",
                    "mirror pixels given their reflection, summed over the views"},
    StatDeclaration{"mirror.pixels_at_limit", kCount, "pixels", "z-buffers",
                    "mirror and layer pixels seen at --max-depth reflections and transmissions: "
                    "their mirrored and transmitted shares dropped, as the tracer drops them"},
    // Planar transparent layers with ior 1 (full mode): the view drawn again without the layer.
    StatDeclaration{"layer.views", kCount, "views", "z-buffers",
                    "views drawn behind planar transparent layers of ior 1: one per layer seen, "
                    "per level (full mode)"},
    StatDeclaration{"layer.pixels", kCount, "pixels", "z-buffers",
                    "layer pixels given what lies behind them by the over operator, summed over "
                    "the views"},
    // Shadows drawn by the z-buffers (full mode).
    StatDeclaration{"shadow_map.maps", kCount, "maps", "raster",
                    "shadow cube maps drawn, one per light sample"},
    StatDeclaration{"shadow_map.faces", kCount, "faces", "raster", "cube faces drawn: 6 per map"},
    StatDeclaration{"shadow_map.size", kCount, "texels", "raster", "a cube face's side"},
    StatDeclaration{"shadow_map.texels", kCount, "texels", "raster",
                    "texels drawn into the lights' shadow maps"},
    StatDeclaration{"shadow_map.batches", kCount, "batches", "raster",
                    "groups of maps drawn and sampled together within the texel budget"},
    StatDeclaration{"shadows.cubes", kCount, "maps", "softraster",
                    "shadow cubes drawn, one per light sample"},
    StatDeclaration{"shadows.map_size", kCount, "texels", "softraster", "a cube face's side"},
    StatDeclaration{"shadows.triangles_setup", kCount, "triangles", "softraster",
                    "triangles set up in the lights' shadow cubes"},
    StatDeclaration{"shadows.fragments", kCount, "fragments", "softraster",
                    "fragments tested in the lights' shadow cubes"},
    StatDeclaration{"shadows.hiz_blocks_rejected", kCount, "blocks", "softraster",
                    "8×8 blocks of the shadow cubes skipped whole by hierarchical z"},
    StatDeclaration{"memory.shadow_bytes", kCount, "bytes", "softraster",
                    "the shadow cubes of one batch, their scratch and set-up triangles"},
    // Work of the pixel-major loop.
    StatDeclaration{"rays.primary", kCount, "rays", "tracers, hybrids",
                    "camera rays: made, traced, and their hit or the background shaded"},
    StatDeclaration{"rays.shadow", kCount, "rays", "tracers, hybrids",
                    "shadow rays traced (any hit: the first one ends them)"},
    StatDeclaration{"rays.reflection", kCount, "rays", "tracers, hybrids",
                    "reflection rays traced"},
    StatDeclaration{"rays.refraction", kCount, "rays", "tracers, hybrids",
                    "refraction rays traced"},
    StatDeclaration{"rays.primary_culled", kCount, "pixels", "tracers, hybrids",
                    "pixels outside the scene's screen bounds, background without a camera ray: "
                    "rays.primary + rays.primary_culled (+ hybrid.background in the hybrids) is "
                    "the pixel count"},
    StatDeclaration{"bvh.nodes_visited", kCount, "nodes", "tracers but embree, hybrids",
                    "BVH nodes visited by every ray: child boxes tested"},
    StatDeclaration{"primitive_tests", kCount, "tests", "tracers but embree, hybrids",
                    "ray–primitive intersection tests"},
    StatDeclaration{"primitives", kCount, "primitives", "tracers, hybrids",
                    "primitives traced: triangles and analytic objects"},
    StatDeclaration{"triangles", kCount, "triangles", "tracers, hybrids", "triangles traced"},
    StatDeclaration{"bvh.width", kCount, "children", "raytrace, hybrids (a BVH)",
                    "children per BVH node: 8 for the wide BVH, 2 for the binary one"},
    StatDeclaration{"bvh.nodes", kCount, "nodes", "raytrace, hybrids (a BVH)",
                    "inner nodes of the BVH (the wide one's and the binary one it was collapsed "
                    "from)"},
    StatDeclaration{"bvh.leaves", kCount, "leaves", "raytrace, hybrids (a BVH)",
                    "leaves of the BVH"},
    StatDeclaration{"bvh.max_depth", kCount, "levels", "raytrace, hybrids (a BVH)",
                    "the deepest leaf's depth"},
    StatDeclaration{"bvh.triangle_blocks", kCount, "blocks", "raytrace, hybrids (wide BVH)",
                    "blocks of 4 triangles the wide BVH's leaves hold"},
    StatDeclaration{"bvh.node_fill", kRatio, "fraction", "raytrace, hybrids (wide BVH)",
                    "share of the wide nodes' child slots used"},
    StatDeclaration{"bvh.block_fill", kRatio, "fraction", "raytrace, hybrids (wide BVH)",
                    "share of the triangle blocks' slots used"},
    StatDeclaration{"bvh.sah_cost", kRatio, "cost", "raytrace_bvh2",
                    "the binary BVH's surface-area-heuristic cost"},
    StatDeclaration{"bvh.bytes", kCount, "bytes", "raytrace, hybrids (a BVH), embree",
                    "memory the acceleration structure holds (Embree's: what its build "
                    "allocated and kept, by its memory monitor, without its copy of the "
                    "geometry)"},
    // The hybrids' split of the work.
    StatDeclaration{"hybrid.rebuilt", kCount, "pixels", "hybrids",
                    "pixels whose primary hit is rebuilt from the z-buffer's ids, no ray"},
    StatDeclaration{"hybrid.fallback_traced", kCount, "pixels", "hybrids",
                    "pixels the z-buffer could not settle, traced as primary rays"},
    StatDeclaration{"hybrid.fallback_missed", kCount, "pixels", "hybrids",
                    "of those traced, the ones whose named primitive the ray missed "
                    "(silhouettes, edges)"},
    StatDeclaration{"hybrid.csg_pixels", kCount, "pixels", "hybrids",
                    "pixels (and samples) where a CSG object is seen, intersected besides the "
                    "z-buffer's hit"},
    StatDeclaration{"hybrid.approximated_pixels", kCount, "pixels", "hybrids",
                    "pixels (and samples) whose hit is a shape the z-buffer would draw only "
                    "approximately (an analytic sphere, disc or CSG solid: the hybrids leave them "
                    "out of its pass), intersected besides the z-buffer's hit: in front of what it "
                    "drew, or where it drew nothing"},
    StatDeclaration{"hybrid.background", kCount, "pixels", "hybrids",
                    "empty pixels left as background without a ray, inside the scene's screen "
                    "bounds: rays.primary + hybrid.background + rays.primary_culled is the pixel "
                    "count"},
    StatDeclaration{"hybrid.zbuffer_passes", kCount, "passes", "hybrids",
                    "z-buffer passes drawn: 1, or 1 + one per sample of an accumulation buffer"},
    // Phase times.
    StatDeclaration{"time.build", kSeconds, "s", "tracers, hybrids",
                    "what the renderer builds per scene before its first frame (its BVH)"},
    StatDeclaration{"time.bvh_build", kSeconds, "s", "raytrace, hybrids (a BVH)",
                    "building the BVH, within time.build"},
    StatDeclaration{"time.render", kSeconds, "s", "every renderer", "the frame"},
    StatDeclaration{"time.visibility", kSeconds, "s", "tracers, hybrids, softraster",
                    "the frame until the primary hits are known (tracers: as the threads' time "
                    "divides; softraster: setup, clearing the z-buffer, binning, raster)"},
    StatDeclaration{"time.shade", kSeconds, "s", "tracers, hybrids, softraster",
                    "the frame after the primary hits: surfaces, AOVs, shading, later rays"},
    StatDeclaration{"time.setup", kSeconds, "s", "z-buffers",
                    "raster: the render target made; softraster: triangles transformed and "
                    "set up"},
    StatDeclaration{"time.upload", kSeconds, "s", "raster", "vertex data sent to the GL"},
    StatDeclaration{"time.bin", kSeconds, "s", "softraster", "triangles binned to tiles"},
    StatDeclaration{"time.raster", kSeconds, "s", "softraster",
                    "tiles rasterized: coverage and depth"},
    StatDeclaration{"time.cost", kSeconds, "s", "raster", "the fragment-count pass (the cost AOV)"},
    StatDeclaration{"time.readback", kSeconds, "s", "z-buffers",
                    "the z-buffer's results copied into the frame buffers"},
    StatDeclaration{"time.shadow_maps", kSeconds, "s", "z-buffers",
                    "the lights' shadow maps drawn (full mode)"},
    StatDeclaration{"time.shadows", kSeconds, "s", "softraster",
                    "shadows in all: cubes drawn and sampled (full mode)"},
    StatDeclaration{"time.dof_blur", kSeconds, "s", "z-buffers",
                    "depth of field as a post-process blur (--zbuffer-dof blur)"},
    StatDeclaration{"time.accumulation", kSeconds, "s", "z-buffers",
                    "the accumulation buffer's sample passes, each drawn and shaded whole"},
    StatDeclaration{"time.mirrors", kSeconds, "s", "z-buffers",
                    "planar mirrors' reflected views, drawn, shaded and composited"},
    StatDeclaration{"time.cube_maps", kSeconds, "s", "z-buffers",
                    "cube maps of curved mirrors and transparent objects, drawn, shaded and "
                    "looked up"},
    StatDeclaration{"time.csg", kSeconds, "s", "z-buffers",
                    "CSG solids: their leaves' depth passes and the per-pixel combination "
                    "(`raster`: with the readback of each pass, part of `time.render` and, for the "
                    "shadow cubes' faces, of `time.shadow_maps`)"},
    StatDeclaration{"time.zbuffer", kSeconds, "s", "hybrids", "the z-buffer passes"},
    StatDeclaration{"time.trace", kSeconds, "s", "hybrids",
                    "the tracer's part: hits rebuilt, rays traced, shading"},
};

std::string_view kind_name(StatKind kind) {
  switch (kind) {
    case StatKind::Count:
      return "count";
    case StatKind::Seconds:
      return "seconds";
    case StatKind::Ratio:
      return "ratio";
  }
  return "?";
}

}  // namespace

std::span<const StatDeclaration> stat_declarations() {
  return kStats;
}

const StatDeclaration* find_stat(std::string_view name) {
  for (;;) {
    for (const StatDeclaration& s : kStats)
      if (s.name == name) return &s;
    constexpr std::string_view kZbuffer = "zbuffer.";
    if (name.substr(0, kZbuffer.size()) != kZbuffer) return nullptr;
    name.remove_prefix(kZbuffer.size());
  }
}

StatKind stat_kind(std::string_view name) {
  const StatDeclaration* s = find_stat(name);
  return s ? s->kind : StatKind::Count;
}

std::string stats_markdown_table() {
  std::string table =
      "| stat | kind | unit | reported by | what it measures |\n|---|---|---|---|---|\n";
  for (const StatDeclaration& s : kStats) {
    table += "| `";
    table += s.name;
    table += "` | ";
    table += kind_name(s.kind);
    table += " | ";
    table += s.unit;
    table += " | ";
    table += s.reported_by;
    table += " | ";
    table += s.measures;
    table += " |\n";
  }
  return table;
}

}  // namespace rvr
