// Every renderer in one table (renderers/src/registry.cpp): its name, its loop order, what it
// is, how to make it. The command line, the tests and the benchmarks ask this table; none keeps
// a list of its own, so a new renderer is one entry there plus its implementation.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/renderers/prepared_renderer.h"

namespace rvr {

// The loop orders the project compares.
enum class LoopOrder {
  TriangleMajor,  // for each triangle, for each covered pixel: the z-buffers
  PixelMajor,     // for each pixel, for each object: the tracers
  Hybrid,         // a z-buffer for primary visibility, then rays per pixel: the hybrids
};
const char* to_string(LoopOrder order);   // "for each triangle, for each pixel", ...
const char* short_name(LoopOrder order);  // "triangle-major", "pixel-major", "hybrid"

// What a renderer is made with, beside the per-frame RenderOptions.
struct RendererConfig {
  GlBackend gl = GlBackend::Default;  // raster: where its GL context comes from
};

// A setting of one table entry that tests and benchmarks run under a name of its own,
// "<entry>_<suffix>" (raytrace_bvh2, softraster_nohiz). What it changes, so that a benchmark
// can pick the variants its question is about:
enum class VariantOf {
  Accelerator,    // the tracer's early rejection (--accel)
  HierarchicalZ,  // the z-buffer's early rejection (--hiz)
  GlContext,      // where the GL context comes from (--gl)
};

struct RendererVariant {
  std::string suffix;  // "bvh2"
  VariantOf of;
  std::string description;
  void (*apply)(RendererConfig& config, RenderOptions& options);
};

struct RendererInfo {
  std::string name;  // on the command line: -r NAME
  LoopOrder order;
  std::string description;  // one line, for --help
  Expected<std::unique_ptr<Renderer>> (*create)(const RendererConfig& config);
  // Optional: what can be built once per scene and options before frames are rendered (see
  // PreparedRenderer). Null when there is nothing; prepare_renderer() then renders plainly.
  Expected<std::unique_ptr<PreparedRenderer>> (*prepare)(const Scene& scene,
                                                         const RendererConfig& config,
                                                         const RenderOptions& options) = nullptr;
  std::vector<RendererVariant> variants = {};
};

// The table, in the order the renderers are documented: raster, softraster, raytrace, embree,
// hybrid, hybrid_soft.
const std::vector<RendererInfo>& renderers();

// Null for a name not in the table.
const RendererInfo* find_renderer(const std::string& name);

// "raster, softraster, raytrace, embree, hybrid, hybrid_soft".
std::string renderer_name_list();

// A bad name is a BadInput error listing the known ones.
Expected<std::unique_ptr<Renderer>> make_renderer(const std::string& name,
                                                  const RendererConfig& config = {});
Expected<std::unique_ptr<Renderer>> make_renderer(const std::string& name, GlBackend gl);

// A table entry as it is, or one of its variants.
struct RendererChoice {
  std::string name;  // "raytrace", "raytrace_bvh2"
  const RendererInfo* info = nullptr;
  const RendererVariant* variant = nullptr;  // null: the entry as it is

  // The variant's changes (none for the entry itself) applied to `config` and `options`.
  void apply(RendererConfig& config, RenderOptions& options) const;
};

// Every entry followed by its variants, in table order: raster, raster_egl, softraster,
// softraster_nohiz, raytrace, raytrace_bvh2, raytrace_none, embree, hybrid, hybrid_soft.
std::vector<RendererChoice> renderer_choices();

// An entry or a variant by its name; a bad name is a BadInput error listing the known ones.
Expected<RendererChoice> find_renderer_choice(const std::string& name);

// The choice made and prepared for one scene (its variant applied to copies of `config` and
// `options`): the entry's prepare hook when it has one, else the renderer rendering the scene
// afresh each time.
Expected<std::unique_ptr<PreparedRenderer>> prepare_renderer(const RendererChoice& choice,
                                                             const Scene& scene,
                                                             RendererConfig config,
                                                             RenderOptions options);

}  // namespace rvr
