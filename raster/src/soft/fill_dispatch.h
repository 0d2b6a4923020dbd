// The per-pixel kernels of one instruction set (rvr/core/isa.h picks which).
#pragma once

#include "rvr/core/isa.h"
#include "soft/fill_kernel.h"

namespace rvr::soft {

// The caller must have checked cpu_supports(isa).
const FillKernels& fill_kernels(Isa isa);

}  // namespace rvr::soft
