#pragma once
// Host data seen through the kernels' own structs (host/KernelCode.h).
#include "KernelCode.h"
#include "distributions/EnvmapDistribution.h"
#include "distributions/ProductTables.h"

namespace misalloc {

kern::EnvmapView makeEnvmapView(const EnvmapTables& tables, float coskExponent);

kern::ProductView makeProductView(const ProductTables& tables);

}  // namespace misalloc
