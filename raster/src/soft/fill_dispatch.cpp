#include "soft/fill_dispatch.h"

namespace rvr::soft {

const FillKernels& fill_kernels(Isa isa) {
  switch (isa) {
    case Isa::Avx512:
      return isa_avx512::kFillKernels;
    case Isa::Avx2:
      return isa_avx2::kFillKernels;
    case Isa::Sse:
      break;
  }
  return isa_sse::kFillKernels;
}

}  // namespace rvr::soft
