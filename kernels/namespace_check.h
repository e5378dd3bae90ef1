// Included at the top of every kernel header, outside its include guard, so that it
// runs at every inclusion. In C++ the kernel headers belong inside namespace
// misalloc::kern (host/KernelCode.h, or a file that opens that namespace after
// including it, as host/alloc/GridSearch.cpp does for gridsearch.h); included anywhere
// else, they would put their functions, types and constants into another namespace.
// This stops the build there. In OpenCL C it is empty.
#ifndef __OPENCL_VERSION__
struct MaKernelNamespaceProbe;
static_assert(__is_same(MaKernelNamespaceProbe, ::misalloc::kern::MaKernelNamespaceProbe),
              "kernels/*.h compile as C++ only inside namespace misalloc::kern: include host/KernelCode.h");
#endif
