// A renderer bound to one scene, with what depends only on the scene and options built already.
#pragma once

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"

namespace rvr {

// The tracers build their acceleration structure here, once, so that render() repeats the
// frame alone: benchmarks prepare outside the timed loop. Holds a reference to the scene.
class PreparedRenderer {
 public:
  virtual ~PreparedRenderer() = default;
  virtual Expected<RenderOutput> render() = 0;
};

}  // namespace rvr
