// Probing the CPU for rvr info (see cpu_probe.h).
#include "cpu_probe.h"

#include <csignal>
#include <fstream>
#include <initializer_list>

namespace rvr::cli {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(colon + 2);
    }
  }
  return "unknown";
}

// The vector instructions the baseline code is built for; the SIMD kernels are compiled for
// several and picked at run time (rvr/core/isa.h), as Embree picks its own.
const char* built_simd() {
#if defined(__AVX512F__)
  return "AVX-512 (512-bit)";
#elif defined(__AVX2__)
  return "AVX2 (256-bit)";
#elif defined(__AVX__)
  return "AVX (256-bit)";
#else
  return "SSE2 (128-bit)";
#endif
}

// Vector extensions the CPU reports in /proc/cpuinfo.
std::string cpu_simd() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("flags", 0) != 0) continue;
    std::string found;
    for (const char* f : {"sse4_2", "avx", "avx2", "avx512f"}) {
      if ((" " + line + " ").find(std::string(" ") + f + " ") != std::string::npos)
        found += (found.empty() ? "" : ", ") + std::string(f);
    }
    return found.empty() ? "none of SSE4.2, AVX, AVX2, AVX-512" : found;
  }
  return "unknown (no /proc/cpuinfo)";
}

}  // namespace rvr::cli
