// Renders through the renderer table for tests that compare renderers: a built-in scene at a
// test's size, and one frame of a named renderer (GL through OSMesa) under given options, a
// failure recorded and an empty output returned on error.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "rvr/core/expected.h"
#include "rvr/core/gl_backend.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/renderers/registry.h"
#include "rvr/scene_io/scene_loader.h"

namespace rvr::test {

inline Scene small_builtin_scene(const std::string& name) {
  Scene scene = make_builtin_scene(name).value();
  scene.image.width = 128;
  scene.image.height = 96;
  return scene;
}

inline RenderOutput table_render(const std::string& renderer, const Scene& scene,
                                 const RenderOptions& options) {
  auto r = make_renderer(renderer, GlBackend::OsMesa);
  EXPECT_TRUE(r.ok()) << renderer;
  if (!r.ok()) return RenderOutput{};
  Expected<RenderOutput> out = r.value()->render(scene, options);
  EXPECT_TRUE(out.ok()) << renderer << ": " << (out.ok() ? "" : out.error().message);
  return out.ok() ? std::move(out).value() : RenderOutput{};
}

}  // namespace rvr::test
