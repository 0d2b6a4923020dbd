// softraster's per-pixel and setup kernels compiled for sse (flags in raster/CMakeLists.txt).
#define RVR_KERNEL_NS isa_sse
#define RVR_KERNEL_NAME "sse"
#include "fill_kernels.inl"
#include "setup_kernels.inl"
// The table last: it names both kernels.
#include "kernel_table.inl"
