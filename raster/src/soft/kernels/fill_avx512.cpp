// softraster's per-pixel kernels compiled for avx512 (flags in raster/CMakeLists.txt).
#define RVR_KERNEL_NS isa_avx512
#define RVR_KERNEL_NAME "avx512"
#include "fill_kernels.inl"
