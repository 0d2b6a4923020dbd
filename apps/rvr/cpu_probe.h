// What rvr info says about the CPU: its model, the SIMD the build assumes and what the CPU has.
// Private to apps/rvr.
#pragma once

#include <string>

namespace rvr::cli {

std::string cpu_model();
// The vector instructions the baseline code is built for; the SIMD kernels are compiled for
// several and picked at run time (rvr/core/isa.h), as Embree picks its own.
const char* built_simd();
// Vector extensions the CPU reports in /proc/cpuinfo.
std::string cpu_simd();

}  // namespace rvr::cli
