#include "rvr/core/isa.h"

#include <cstdlib>
#include <cstring>
#include <iterator>

namespace rvr {

const char* to_string(Isa isa) {
  switch (isa) {
    case Isa::Sse:
      return "sse";
    case Isa::Avx2:
      return "avx2";
    case Isa::Avx512:
      return "avx512";
  }
  return "?";
}

bool cpu_supports(Isa isa) {
  // libgcc's probe checks CPUID and, for AVX and AVX-512, that the OS enables the registers
  // (XGETBV), so a "yes" here means the instructions can run.
  __builtin_cpu_init();
  switch (isa) {
    case Isa::Sse:
      return true;  // SSE2 is baseline x86-64; the SSE kernels use nothing newer
    case Isa::Avx2:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
             __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
             __builtin_cpu_supports("popcnt");
    case Isa::Avx512:
      return cpu_supports(Isa::Avx2) && __builtin_cpu_supports("avx512f") &&
             __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx512bw");
  }
  return false;
}

namespace {

Isa best_of(const std::function<bool(Isa)>& supports) {
  if (supports(Isa::Avx512)) return Isa::Avx512;
  if (supports(Isa::Avx2)) return Isa::Avx2;
  return Isa::Sse;
}

}  // namespace

Isa best_supported_isa() {
  return best_of(cpu_supports);
}

Expected<Isa> selected_isa() {
  return select_isa(std::getenv("RVR_ISA"), cpu_supports);
}

Expected<Isa> select_isa(const char* forced, const std::function<bool(Isa)>& supports) {
  if (!forced || !*forced) return best_of(supports);
  for (Isa isa : kAllIsas) {
    if (std::strcmp(forced, to_string(isa)) != 0) continue;
    if (!supports(isa))
      return bad_input(std::string("RVR_ISA=") + forced + ": this CPU cannot run " + forced +
                       " kernels (best available: " + to_string(best_of(supports)) + ")");
    return isa;
  }
  std::string names;  // "sse, avx2 or avx512"
  for (Isa isa : kAllIsas) {
    if (isa != kAllIsas[0]) names += isa == std::end(kAllIsas)[-1] ? " or " : ", ";
    names += to_string(isa);
  }
  return bad_input(std::string("RVR_ISA=") + forced + ": unknown (use " + names + ")");
}

Expected<Isa> resolve_isa(const std::optional<Isa>& requested) {
  if (!requested) return selected_isa();
  if (!cpu_supports(*requested))
    return bad_input(std::string("this CPU cannot run the ") + to_string(*requested) + " kernels");
  return *requested;
}

std::string describe_isa_choice() {
  Expected<Isa> isa = selected_isa();
  if (!isa) return isa.error().message;
  const char* forced = std::getenv("RVR_ISA");
  return std::string(to_string(*isa)) +
         (forced && *forced ? " (forced by RVR_ISA)" : " (chosen from the CPU)");
}

}  // namespace rvr
