// What `rvr study` adds to a study request and result beside the library: the renderers run by
// default (one per loop order) and the machine the study ran on. The Python module's rvr.study
// sets them up here too.
#pragma once

#include <string>
#include <vector>

#include "rvr/study/study.h"

namespace rvr {

// The renderers a study runs by default: one per loop order.
std::vector<std::string> default_study_renderers();

// The defaults, then those of `extra` not among them, in order.
std::vector<std::string> study_renderers(const std::vector<std::string>& extra);

// The CPU, its threads, the SIMD kernels chosen and the versions of rvr (`version`), Embree,
// TBB and the compiler.
study::MachineInfo machine_info(const std::string& version);

}  // namespace rvr
