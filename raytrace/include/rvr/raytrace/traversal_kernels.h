// The wide BVH's traversal kernels of one instruction set, picked once (rvr/core/isa.h).
#pragma once

#include "rvr/core/isa.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

// The kernels compiled for `isa`. The caller must have checked cpu_supports(isa).
const TraversalKernels& traversal_kernels(Isa isa);

}  // namespace rvr
