// softraster's per-pixel kernels compiled for sse (flags in raster/CMakeLists.txt).
#define RVR_KERNEL_NS isa_sse
#define RVR_KERNEL_NAME "sse"
#include "fill_kernels.inl"
