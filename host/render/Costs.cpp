#include "render/Costs.h"

#include <fmt/format.h>

#include <cmath>

#include "Error.h"
#include "NumberList.h"

namespace misalloc {

std::vector<double> measureCosts(StageSampler& calibration, int spp) {
  const Scene& scene = calibration.scene();
  const int pixels = scene.pixelCount(), M = scene.techniqueCount();
  std::vector<double> costs(M);
  for (int k = 0; k < M; ++k) {
    StagePlan plan;
    plan.techniqueCount = M;
    plan.stageSamples = spp;
    plan.counts.assign(size_t(pixels) * M, 0);
    plan.firstIndex.assign(size_t(pixels) * M, 0u);
    for (int p = 0; p < pixels; ++p) plan.counts[size_t(p) * M + k] = spp;
    calibration.run(plan, 1);  // the first launch of a kernel pays for its JIT
    costs[k] = calibration.run(plan, 2).kernelSeconds / (double(pixels) * spp);
  }
  return costs;
}

std::vector<double> parseCosts(const std::string& list, int techniqueCount) {
  std::vector<double> costs =
      parseNumberList("--cost", list, list, size_t(techniqueCount), "one cost per technique");
  for (double c : costs)
    if (c <= 0) throw InputError(fmt::format("--cost {}: costs must be positive, got {}", list, c));
  return costs;
}

}  // namespace misalloc
