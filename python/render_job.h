// A render run on a thread of its own while the calling Python thread waits without the GIL,
// looking at Python's signals every few milliseconds: Ctrl-C raises KeyboardInterrupt at once.
// The renderers have no way to be stopped part way, so an interrupted render is abandoned: it
// finishes on its thread, its result dropped, and the interpreter waits for it at exit.
#pragma once

#include <memory>

#include "rvr/shared/expected.h"
#include "rvr/shared/renderer.h"
#include "rvr/shared/scene.h"

namespace rvr::python {

struct RenderResultWithTime {
  Expected<RenderOutput> output = internal_error("not rendered");
  double seconds = 0.0;  // the render alone
};

// Renders `scene` with `renderer` and `options`; called with the GIL held. Throws
// pybind11::error_already_set when a signal handler raised (KeyboardInterrupt).
RenderResultWithTime render_interruptibly(std::shared_ptr<const Scene> scene,
                                          std::unique_ptr<Renderer> renderer,
                                          const RenderOptions& options);

// Waits (without the GIL) for every abandoned render to finish; registered with atexit.
void wait_for_abandoned_renders();

}  // namespace rvr::python
