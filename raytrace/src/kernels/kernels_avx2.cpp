// The wide-BVH traversal kernels compiled for avx2 (flags in raytrace/CMakeLists.txt).
#define RVR_KERNEL_NS isa_avx2
#define RVR_KERNEL_NAME "avx2"
#include "wide_kernels.inl"
