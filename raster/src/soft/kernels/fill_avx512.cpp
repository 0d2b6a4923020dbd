// softraster's per-pixel and setup kernels compiled for avx512 (flags: RVR_KERNEL_FLAGS_avx512 in
// the top-level CMakeLists.txt and raster/CMakeLists.txt's own).
#define RVR_KERNEL_NS isa_avx512
#define RVR_KERNEL_NAME "avx512"
#include "fill_kernels.inl"
#include "setup_kernels.inl"
// The table last: it names both kernels.
#include "kernel_table.inl"
