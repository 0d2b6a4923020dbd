// The OpenGL z-buffer renderer: "for each triangle, for each covered pixel", run by Mesa's
// llvmpipe off-screen on the CPU. No GL type appears in this header.
#pragma once

#include <memory>
#include <string>

#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr {

const char* to_string(GlBackend backend);  // "default", "osmesa", "egl"

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
