#include "soft/fill_dispatch.h"

namespace rvr::soft {

const FillKernels& fill_kernels(Isa isa) {
  return dispatch_isa(isa, isa_sse::kFillKernels, isa_avx2::kFillKernels, isa_avx512::kFillKernels);
}

}  // namespace rvr::soft
