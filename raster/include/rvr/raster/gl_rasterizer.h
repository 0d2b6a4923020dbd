// The OpenGL z-buffer renderer: "for each triangle, for each covered pixel", run by Mesa's
// llvmpipe off-screen on the CPU. No GL type appears in this header.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rvr/shared/expected.h"
#include "rvr/shared/renderer.h"

namespace rvr {

// Where the OpenGL context comes from. Both run Mesa's llvmpipe; they differ only in how the
// context is made. Default: OSMesa, or EGL surfaceless when OSMesa cannot be loaded (the
// rasterizer then says so in its warnings).
enum class GlBackend { Default, OsMesa, Egl };
const char* to_string(GlBackend backend);  // "default", "osmesa", "egl"

// What the GL context reports, for `rvr info` and bug reports.
struct GlInfo {
  std::string backend;   // "osmesa" or "egl": the one in use
  std::string version;   // GL_VERSION
  std::string renderer;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string vendor;    // GL_VENDOR
  std::string glsl_version;
  std::vector<std::string> warnings;  // e.g. that the default fell back to EGL, and why
};

// Makes a context and reads its strings; an Internal error when no usable context exists.
Expected<GlInfo> query_gl_info(GlBackend backend = GlBackend::Default);

class GlRasterizer : public Renderer {
 public:
  explicit GlRasterizer(GlBackend backend = GlBackend::Default);
  ~GlRasterizer() override;
  std::string name() const override { return "raster"; }
  // Errors: Internal (exit 3) when no context can be made or the driver cannot render.
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;  // the GL context and resources, created on first render
};

}  // namespace rvr
