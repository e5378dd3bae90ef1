#pragma once
// The kernels' shared functions (kernels/*.h) compiled as C++ in namespace
// misalloc::kern: host references, tests and the OpenMP benchmark peer call exactly
// the maths that the OpenCL kernels run.
#include <Random123/philox.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>

// Every kernel header checks that it is included inside this namespace
// (kernels/namespace_check.h).
namespace misalloc::kern {
#include "estimator.h"
#include "fallbacks.h"
#include "gridsearch.h"
#include "pixel.h"
#include "pixel_layout.h"
#include "pixel_pairs.h"
#include "stats.h"
}  // namespace misalloc::kern
