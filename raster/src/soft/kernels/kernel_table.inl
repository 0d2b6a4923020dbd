// The one exported symbol of a softraster kernel unit: its table (after fill_kernels.inl and
// setup_kernels.inl; tests/check_kernel_symbols.sh checks that nothing else is exported).
namespace rvr::soft {
namespace RVR_KERNEL_NS {

extern const FillKernels kFillKernels = {RVR_KERNEL_NAME, fill, setup_batch, project_vertices};

}  // namespace RVR_KERNEL_NS
}  // namespace rvr::soft
