#pragma once
#include <fmt/format.h>

#include <CL/opencl.hpp>
#include <stdexcept>

namespace misalloc {

// Binds every argument of `kernel` in the order of its signature. The count is checked
// against the built kernel, so that a signature and its host call cannot drift apart
// by an argument added on one side only.
template <typename... Args>
void bindKernelArgs(cl::Kernel& kernel, const Args&... args) {
  const cl_uint expected = kernel.getInfo<CL_KERNEL_NUM_ARGS>();
  if (expected != sizeof...(Args))
    throw std::logic_error(fmt::format("kernel {} takes {} arguments, the host binds {}",
                                       kernel.getInfo<CL_KERNEL_FUNCTION_NAME>(), expected, sizeof...(Args)));
  cl_uint index = 0;
  (kernel.setArg(index++, args), ...);
}

}  // namespace misalloc
