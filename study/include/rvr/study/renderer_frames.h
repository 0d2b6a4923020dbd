// The study's frames from the real renderers: the built-in scene at the study's size, each
// renderer prepared through the renderer table outside the timed frames (as rvr_bench does),
// its preparation timed on its own.
#pragma once

#include <stddef.h>

#include <memory>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/study/run_study.h"
#include "rvr/study/sweep_plan.h"

namespace rvr::study {

// The FrameSource of builtin:<family>:<n> (or n copies of the family's file) at
// width × width·3/4, with `renderers` prepared in `mode`, each having rendered one untimed frame.
Expected<std::unique_ptr<FrameSource>> prepare_frames(const std::vector<std::string>& renderers,
                                                      RenderMode mode, const Family& family,
                                                      size_t n, int width);

// builtin:<family>:<n>, or n copies of the family's file, at width × width·3/4.
Expected<Scene> family_scene(const Family& family, size_t n, int width);

// Sessions in this process: each scene prepared afresh in each (kind "preparation"). What the
// Python module and tests use; the CLI starts a process per session instead.
StartSession in_process_sessions(const StudyRequest& request);

// The stats of a frame that count work, not time or memory (measurement.h's counters).
bool is_work_counter(const std::string& stat);

}  // namespace rvr::study
