// The renderer table. To add a renderer: implement it (raster/ or raytrace/, behind
// rvr::Renderer) and add one entry to the table in renderers() below; the command line (-r, --help,
// rvr info), the conformance, progress and NaN tests and the benchmarks all pick it up from here.
#include "rvr/renderers/registry.h"

#include <memory>
#include <set>
#include <utility>
#include <variant>

#include "prepared_hybrid.h"
#include "prepared_tracer.h"
#include "rvr/core/check.h"
#include "rvr/core/framebuffers.h"
#include "rvr/hybrid/hybrid_renderer.h"
#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raster/soft_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"

namespace rvr {

namespace {

// Renderer R with the scene's exposure applied to its colour after it has rendered
// (apply_exposure): the one place every renderer of the table gets it, so that it is the
// same transform in all of them (the prepared tracer and hybrids apply it in
// PreparedOverGeometry::render).
template <class R>
class Exposed : public R {
 public:
  using R::R;
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options) override {
    Expected<RenderOutput> out = R::render(scene, options);
    if (out.ok()) apply_exposure(out->buffers, scene.image.exposure);
    return out;
  }
};

template <class R, class... Args>
Expected<std::unique_ptr<Renderer>> make(Args... args) {
  return std::unique_ptr<Renderer>(std::make_unique<Exposed<R>>(args...));
}

// The table's own invariants: every entry can be made, and the names the command line takes
// (renderer names and name_variant) are unique, so -r picks one renderer.
bool check_table(const std::vector<RendererInfo>& table) {
  std::set<std::string> names;
  for (const RendererInfo& r : table) {
    RVR_CHECK(!r.name.empty() && r.create, "every renderer has a name and a factory");
    RVR_CHECK(names.insert(r.name).second, "renderer name '", r.name, "' is in the table twice");
    for (const RendererVariant& v : r.variants) {
      RVR_CHECK(v.apply, "variant '", v.suffix, "' of ", r.name, " changes something");
      RVR_CHECK(names.insert(r.name + "_" + v.suffix).second, "renderer name '", r.name, "_",
                v.suffix, "' is in the table twice");
    }
  }
  return true;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

}  // namespace

const char* to_string(LoopOrder order) {
  switch (order) {
    case LoopOrder::TriangleMajor:
      return "for each triangle, for each pixel";
    case LoopOrder::PixelMajor:
      return "for each pixel, for each object";
    case LoopOrder::Hybrid:
      return "for each triangle, for each pixel; then for each pixel, its rays";
  }
  return "";
}

const char* short_name(LoopOrder order) {
  switch (order) {
    case LoopOrder::TriangleMajor:
      return "triangle-major";
    case LoopOrder::PixelMajor:
      return "pixel-major";
    case LoopOrder::Hybrid:
      return "hybrid";
  }
  return "";
}

// The table, in the order the renderers are documented; a new renderer is one entry here.
// Made on first use, so that tests and benchmarks may read it while registering.
const std::vector<RendererInfo>& renderers() {
  static const std::vector<RendererInfo> table = {
      {
          .name = "raster",
          .order = LoopOrder::TriangleMajor,
          .description = "OpenGL z-buffer (Mesa llvmpipe through OSMesa or EGL, --gl)",
          .create = [](const RendererConfig& c) { return make<GlRasterizer>(c.gl); },
          .variants = {{"egl", VariantOf::GlContext, "its GL context from EGL surfaceless",
                        [](RendererConfig& c, RenderOptions&) { c.gl = GlBackend::Egl; }}},
      },
      {
          .name = "softraster",
          .order = LoopOrder::TriangleMajor,
          .description = "our own CPU z-buffer: tiles, blocks, hierarchical z (--hiz)",
          .create = [](const RendererConfig&) { return make<SoftRasterizer>(); },
          .variants = {{"nohiz", VariantOf::HierarchicalZ,
                        "hierarchical z off: the textbook z-buffer loop",
                        [](RendererConfig&, RenderOptions& o) { o.hiz = false; }}},
      },
      {
          .name = "raytrace",
          .order = LoopOrder::PixelMajor,
          .description =
              "our CPU ray tracer over a wide BVH, a binary BVH or every object (--accel)",
          .create = [](const RendererConfig&) { return make<RayTracer>(); },
          // The BVH is built once per scene (benchmarks build it outside the timed loop).
          .prepare = [](const Scene& s, const RendererConfig&,
                        const RenderOptions& o) { return prepare_tracer(s, o, o.accel); },
          .variants = {{"bvh2", VariantOf::Accelerator, "the binary BVH, one box at a time",
                        [](RendererConfig&, RenderOptions& o) { o.accel = AccelKind::Bvh2; }},
                       {"none", VariantOf::Accelerator, "every object for every ray",
                        [](RendererConfig&, RenderOptions& o) { o.accel = AccelKind::None; }}},
      },
      {
          .name = "embree",
          .order = LoopOrder::PixelMajor,
          .description = "the same tracer with Intel Embree 3 answering the ray queries",
          .create = [](const RendererConfig&) { return make<RayTracer>(AccelKind::Embree); },
          .prepare = [](const Scene& s, const RendererConfig&,
                        const RenderOptions& o) { return prepare_tracer(s, o, AccelKind::Embree); },
      },
      {
          .name = "hybrid",
          .order = LoopOrder::Hybrid,
          .description = "the GL z-buffer's ids for what the eye sees, the tracer for the rest",
          .create =
              [](const RendererConfig& c) { return make<HybridRenderer>(ZBufferKind::Gl, c.gl); },
          .prepare =
              [](const Scene& s, const RendererConfig& c, const RenderOptions& o) {
                return prepare_hybrid(s, o, ZBufferKind::Gl, c.gl);
              },
      },
      {
          .name = "hybrid_soft",
          .order = LoopOrder::Hybrid,
          .description = "hybrid with softraster as the z-buffer",
          .create = [](const RendererConfig&) { return make<HybridRenderer>(ZBufferKind::Soft); },
          .prepare =
              [](const Scene& s, const RendererConfig& c, const RenderOptions& o) {
                return prepare_hybrid(s, o, ZBufferKind::Soft, c.gl);
              },
      },
  };
  [[maybe_unused]] static const bool checked = check_table(table);
  return table;
}

const RendererInfo* find_renderer(const std::string& name) {
  for (const RendererInfo& r : renderers())
    if (r.name == name) return &r;
  return nullptr;
}

std::string renderer_name_list() {
  std::vector<std::string> names;
  for (const RendererInfo& r : renderers()) names.push_back(r.name);
  return joined(names);
}

Expected<std::unique_ptr<Renderer>> make_renderer(const std::string& name,
                                                  const RendererConfig& config) {
  if (const RendererInfo* r = find_renderer(name)) return r->create(config);
  return bad_input("unknown renderer '" + name + "' (known: " + renderer_name_list() + ")");
}

Expected<std::unique_ptr<Renderer>> make_renderer(const std::string& name, GlBackend gl) {
  return make_renderer(name, RendererConfig{gl});
}

void RendererChoice::apply(RendererConfig& config, RenderOptions& options) const {
  if (variant) variant->apply(config, options);
}

std::vector<RendererChoice> renderer_choices() {
  std::vector<RendererChoice> choices;
  for (const RendererInfo& r : renderers()) {
    choices.push_back({r.name, &r, nullptr});
    for (const RendererVariant& v : r.variants)
      choices.push_back({r.name + "_" + v.suffix, &r, &v});
  }
  return choices;
}

Expected<RendererChoice> find_renderer_choice(const std::string& name) {
  std::vector<std::string> names;
  for (const RendererChoice& c : renderer_choices()) {
    if (c.name == name) return c;
    names.push_back(c.name);
  }
  return bad_input("unknown renderer '" + name + "' (known: " + joined(names) + ")");
}

}  // namespace rvr
