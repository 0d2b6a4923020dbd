// The Vec3v probe compiled for sse (flags: RVR_KERNEL_FLAGS_sse in the top-level CMakeLists.txt).
#define RVR_KERNEL_NS isa_sse
#define RVR_KERNEL_NAME "sse"
#include "simd/vec3v_probe.inl"
