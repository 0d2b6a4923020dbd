// The study's sessions as fresh processes: each session starts `rvr study-worker`, which
// prepares the scenes it is asked for and times their frames, answering one JSON line per
// request over a socket on its stdin and stdout. Timing happens in the worker, around the
// frame alone; the parent only sends what to render next.
#pragma once

#include <string>
#include <vector>

#include "rvr/core/renderer.h"
#include "rvr/study/memory_estimate.h"
#include "rvr/study/run_study.h"

namespace rvr::cli {

// Sessions that each start `executable study-worker --mode MODE -r RENDERERS`.
study::StartSession process_sessions(const std::string& executable,
                                     const std::vector<std::string>& renderers, RenderMode mode);

// Memory probes (memory_estimate.h) each taken in a fresh `executable study-worker`.
study::ProbeMemory process_memory_probes(const std::string& executable,
                                         const std::vector<std::string>& renderers,
                                         RenderMode mode);

// The worker's loop: requests from stdin until it closes, answers on stdout. Exit status 0.
int run_study_worker(const std::vector<std::string>& renderers, RenderMode mode);

// The path of the running executable (/proc/self/exe), for starting workers of the same build.
std::string own_executable();

}  // namespace rvr::cli
