#include "rvr/core/isa.h"
#include "rvr/raytrace/traversal_kernels.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

const TraversalKernels& traversal_kernels(Isa isa) {
  return dispatch_isa(isa, isa_sse::kKernels, isa_avx2::kKernels, isa_avx512::kKernels);
}

}  // namespace rvr
