// softraster's per-pixel and setup kernels compiled for sse (flags: RVR_KERNEL_FLAGS_sse in the
// top-level CMakeLists.txt and raster/CMakeLists.txt's own).
#define RVR_KERNEL_NS isa_sse
#define RVR_KERNEL_NAME "sse"
#include "fill_kernels.inl"
#include "setup_kernels.inl"
// The table last: it names both kernels.
#include "kernel_table.inl"
