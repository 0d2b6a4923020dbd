// The shading kernels compiled for sse (flags: RVR_KERNEL_FLAGS_sse in the top-level
// CMakeLists.txt).
#define RVR_KERNEL_NS isa_sse
#define RVR_KERNEL_NAME "sse"
#include "rvr/core/shade_kernel.h"
#include "shade_kernels.inl"

namespace rvr {
namespace RVR_KERNEL_NS {

extern const ShadeKernels kShadeKernels = {RVR_KERNEL_NAME, shade, shade_surfaces, light_needs};

}  // namespace RVR_KERNEL_NS
}  // namespace rvr
