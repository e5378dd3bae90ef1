#pragma once
#include <string>

#include "render/Method.h"
#include "render/Render.h"

namespace misalloc {

// The host memory of the samples a method stores, on each of `samplers` devices
// (`--device LIST`, sampling/TiledSampler.h), and, on the C++ sampler (`onHost`), of
// the grid search's sums, refused up front with the option that asks for it:
// `sppOption` is --spp for render, --budgets for compare. Throws InputError.
void requireStatisticsMemory(const SceneOptions& scene, Method m, const std::string& sppOption, int spp,
                             const AdaptiveOptions& adaptive, bool onHost, int samplers);

}  // namespace misalloc
