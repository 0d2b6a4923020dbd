// The study's frames from the real renderers: the built-in scene at the study's size, each
// renderer prepared through the renderer table outside the timed frames (as rvr_bench does).
#pragma once

#include "rvr/study/run_study.h"

namespace rvr::study {

// Frames of `request.renderers` at request.width x width*3/4 in request.mode.
PrepareFrames renderer_frames(const StudyRequest& request);

}  // namespace rvr::study
