// softraster's per-pixel and setup kernels compiled for avx2 (flags in raster/CMakeLists.txt).
#define RVR_KERNEL_NS isa_avx2
#define RVR_KERNEL_NAME "avx2"
#include "fill_kernels.inl"
#include "setup_kernels.inl"
// The table last: it names both kernels.
#include "kernel_table.inl"
