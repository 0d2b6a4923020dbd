#include "rvr/raytrace/traversal_kernels.h"

namespace rvr {

const TraversalKernels& traversal_kernels(Isa isa) {
  switch (isa) {
    case Isa::Avx512:
      return isa_avx512::kKernels;
    case Isa::Avx2:
      return isa_avx2::kKernels;
    case Isa::Sse:
      break;
  }
  return isa_sse::kKernels;
}

}  // namespace rvr
