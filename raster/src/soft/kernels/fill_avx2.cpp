// softraster's per-pixel and setup kernels compiled for avx2 (flags: RVR_KERNEL_FLAGS_avx2 in the
// top-level CMakeLists.txt and raster/CMakeLists.txt's own).
#define RVR_KERNEL_NS isa_avx2
#define RVR_KERNEL_NAME "avx2"
#include "fill_kernels.inl"
#include "setup_kernels.inl"
// The table last: it names both kernels.
#include "kernel_table.inl"
