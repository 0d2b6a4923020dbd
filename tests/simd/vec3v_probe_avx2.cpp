// The Vec3v probe compiled for avx2 (flags: RVR_KERNEL_FLAGS_avx2 in the top-level CMakeLists.txt).
#define RVR_KERNEL_NS isa_avx2
#define RVR_KERNEL_NAME "avx2"
#include "simd/vec3v_probe.inl"
