// Our own CPU z-buffer renderer: "for each triangle, for each covered pixel", with no GL.
// Triangles are transformed, near-clipped and binned to 64x64 screen tiles; tiles are
// rasterized in parallel (fixed-point edge functions, top-left fill rule, strict-less z-test
// in submission order), then each visible pixel is shaded once with rvr::shade_local.
#pragma once

#include <memory>
#include <string>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr {

class SoftRasterizer : public Renderer {
 public:
  SoftRasterizer();
  ~SoftRasterizer() override;
  std::string name() const override { return "softraster"; }
  Expected<RenderOutput> render(const Scene& scene, const RenderOptions& options) override;

  struct Frame;

 private:
  // The z-buffer state of the last render, cleared and reused by the next one of the same size
  // (as a GL context keeps its framebuffer): tens of MB not reallocated and faulted in again.
  std::unique_ptr<Frame> frame_;
};

}  // namespace rvr
