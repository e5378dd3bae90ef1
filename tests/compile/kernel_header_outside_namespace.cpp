// Must not compile: a kernel header included outside namespace misalloc::kern, after
// host/KernelCode.h (kernels/namespace_check.h stops the build). tests/CMakeLists.txt
// checks that the compiler reports exactly that.
#include "KernelCode.h"

namespace misalloc {
#include "gridsearch.h"
}  // namespace misalloc

int main() { return 0; }
