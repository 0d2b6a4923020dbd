#include "rvr/core/isa.h"
#include "rvr/core/shade_kernel.h"

namespace rvr {

const ShadeKernels& shade_kernels(Isa isa) {
  return dispatch_isa(isa, isa_sse::kShadeKernels, isa_avx2::kShadeKernels,
                      isa_avx512::kShadeKernels);
}

}  // namespace rvr
