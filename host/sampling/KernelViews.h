#pragma once
// Host data seen through the kernels' own structs (host/KernelCode.h).
#include "KernelCode.h"
#include "distributions/EnvmapDistribution.h"
#include "distributions/ProductTables.h"
#include "scene/Scene.h"

namespace misalloc {

kern::EnvmapView makeEnvmapView(const EnvmapTables& tables, float coskExponent);

kern::ProductView makeProductView(const ProductTables& tables);

// Pixel p of the scene as the point it shades: its BRDF, normal and mirror direction.
kern::ShadingPoint makeShadingPoint(const Scene& scene, int pixel);

}  // namespace misalloc
