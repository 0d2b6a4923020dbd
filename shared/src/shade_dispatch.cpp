#include "rvr/shared/shade_kernel.h"

namespace rvr {

const ShadeKernels& shade_kernels(Isa isa) {
  switch (isa) {
    case Isa::Avx512:
      return isa_avx512::kShadeKernels;
    case Isa::Avx2:
      return isa_avx2::kShadeKernels;
    case Isa::Sse:
      break;
  }
  return isa_sse::kShadeKernels;
}

}  // namespace rvr
