// A render run on a thread of its own while the calling Python thread waits without the GIL,
// looking at Python's signals every few milliseconds. When a signal handler raises (Ctrl-C:
// KeyboardInterrupt), the render is cancelled through its ProgressSink, which the renderers look
// at per tile or chunk; the thread is joined and the exception raised: nothing is left running.
#pragma once

#include <memory>
#include <variant>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr::python {

struct RenderResultWithTime {
  Expected<RenderOutput> output = internal_error("not rendered");
  double seconds = 0.0;  // the render alone
};

// Renders `scene` with `renderer` and `options`; called with the GIL held. Throws
// pybind11::error_already_set when a signal handler raised (KeyboardInterrupt), after the
// render has stopped. `options.progress`, when set, is the sink cancelled; else one of its own.
RenderResultWithTime render_interruptibly(std::shared_ptr<const Scene> scene,
                                          std::unique_ptr<Renderer> renderer,
                                          const RenderOptions& options);

// Render threads started and not yet joined (0 whenever no call is inside render_interruptibly).
int running_renders();

}  // namespace rvr::python
