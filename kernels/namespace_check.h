// Included at the top of every kernel header, outside its include guard, so that it
// runs at every inclusion. In C++ the kernel headers belong inside namespace
// misalloc::kern (host/KernelCode.h includes them there); included anywhere else,
// they would put their functions, types and constants into another namespace. This
// stops the build there. In OpenCL C it is empty.
#ifndef __OPENCL_VERSION__
struct MaKernelNamespaceProbe;
static_assert(__is_same(MaKernelNamespaceProbe, ::misalloc::kern::MaKernelNamespaceProbe),
              "kernels/*.h compile as C++ only inside namespace misalloc::kern: include host/KernelCode.h");
#endif
