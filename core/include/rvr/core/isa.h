// Which SIMD kernels run: chosen once from the CPU (as Embree does), or forced with RVR_ISA.
// The binary itself targets baseline x86-64; only kernel translation units are compiled for
// wider instruction sets, and a kernel is never called on a CPU that lacks its instructions.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "rvr/core/expected.h"

namespace rvr {

// The instruction sets the kernels are compiled for (RVR_SIMD_ISAS in the top-level
// CMakeLists.txt lists the same, in the same order), narrowest first.
enum class Isa { Sse, Avx2, Avx512 };
inline constexpr Isa kAllIsas[] = {Isa::Sse, Isa::Avx2, Isa::Avx512};

const char* to_string(Isa isa);  // "sse", "avx2", "avx512"

// What this CPU (and its operating system, which must save the wide registers) can run.
bool cpu_supports(Isa isa);
Isa best_supported_isa();

// The kernel set to use: RVR_ISA=sse|avx2|avx512 when set, otherwise the best the CPU offers.
// A bad value, or an ISA this CPU cannot run, is a BadInput error naming RVR_ISA.
Expected<Isa> selected_isa();

// The decision selected_isa() makes, for a value of RVR_ISA (null or empty: unset) on a CPU that
// runs what `supports` says (so that every outcome can be tested on any CPU).
Expected<Isa> select_isa(const char* forced, const std::function<bool(Isa)>& supports);

// The kernels a render runs: `requested` (RenderOptions::isa) when set, else selected_isa(); a
// BadInput error when this CPU cannot run them.
Expected<Isa> resolve_isa(const std::optional<Isa>& requested);

// For messages: "avx2 (chosen from the CPU)" or "sse (forced by RVR_ISA)".
std::string describe_isa_choice();

// The kernel table of `isa` among one table per instruction set (each kernel family's
// dispatcher: traversal, softraster's fill and setup, shading). Called from baseline code only.
template <class Table>
const Table& dispatch_isa(Isa isa, const Table& sse, const Table& avx2, const Table& avx512) {
  switch (isa) {
    case Isa::Avx512:
      return avx512;
    case Isa::Avx2:
      return avx2;
    case Isa::Sse:
      break;
  }
  return sse;
}

}  // namespace rvr
