// The Vec3v probe compiled for avx512 (flags: RVR_KERNEL_FLAGS_avx512 in the top-level
// CMakeLists.txt).
#define RVR_KERNEL_NS isa_avx512
#define RVR_KERNEL_NAME "avx512"
#include "simd/vec3v_probe.inl"
