// softraster's per-pixel and setup kernels compiled for avx512 (flags in raster/CMakeLists.txt).
#define RVR_KERNEL_NS isa_avx512
#define RVR_KERNEL_NAME "avx512"
#include "fill_kernels.inl"
#include "setup_kernels.inl"
// The table last: it names both kernels.
#include "kernel_table.inl"
