#pragma once
#include <string>
#include <vector>

#include "render/Method.h"
#include "render/Render.h"

namespace misalloc {

// The host memory of the samples the methods store, all held at once (compare keeps
// one sampler per method for a budget), on each of `samplers` devices (`--device
// LIST`, sampling/TiledSampler.h), and, on the C++ sampler (`onHost`), of the grid
// search's sums, refused up front with the options that ask for it: `sppOption` is
// --spp for render, --budgets for compare. Throws InputError.
void requireStatisticsMemory(const SceneOptions& scene, const std::vector<Method>& methods,
                             const std::string& sppOption, int spp, const AdaptiveOptions& adaptive, bool onHost,
                             int samplers);

}  // namespace misalloc
