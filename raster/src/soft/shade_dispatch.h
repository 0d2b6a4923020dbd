// The shading kernels of one instruction set (shared/isa.h picks which).
#pragma once

#include "rvr/shared/isa.h"
#include "soft/shade_kernel.h"

namespace rvr::soft {

// The caller must have checked cpu_supports(isa).
const ShadeKernels& shade_kernels(Isa isa);

}  // namespace rvr::soft
