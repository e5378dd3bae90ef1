#include "sampling/Costs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "Error.h"
#include "NumberList.h"

namespace misalloc {

std::vector<double> measureCosts(StageSampler& calibration, int spp) {
  const Scene& scene = calibration.scene();
  const int pixels = scene.pixelCount(), M = scene.techniqueCount();
  std::vector<StagePlan> plans(M);
  for (int k = 0; k < M; ++k) {
    StagePlan& plan = plans[k];
    plan.techniqueCount = M;
    plan.stageSamples = spp;
    plan.counts.assign(size_t(pixels) * M, 0);
    plan.firstIndex.assign(size_t(pixels) * M, 0u);
    for (int p = 0; p < pixels; ++p) plan.counts[size_t(p) * M + k] = spp;
    calibration.run(plan, 1);  // the first launch of a kernel pays for its JIT
  }
  // Rounds over the techniques in turn, so that a drift of the machine's speed
  // reaches every technique alike, and the median round of each, which a round
  // slowed by another process does not move.
  constexpr int kRounds = 5;
  std::vector<std::vector<double>> seconds(M);
  for (int round = 0; round < kRounds; ++round)
    for (int k = 0; k < M; ++k) seconds[k].push_back(calibration.run(plans[k], 2 + round).kernelSeconds);
  std::vector<double> costs(M);
  for (int k = 0; k < M; ++k) {
    std::nth_element(seconds[k].begin(), seconds[k].begin() + kRounds / 2, seconds[k].end());
    costs[k] = seconds[k][kRounds / 2] / (double(pixels) * spp);
  }
  return costs;
}

std::vector<double> parseCosts(const std::string& list, int techniqueCount) {
  std::vector<double> costs = parseNumberList("--cost", list, list, size_t(techniqueCount), "one cost per technique");
  for (double c : costs)
    if (c <= 0) throw InputError(fmt::format("--cost {}: costs must be positive, got {}", list, c));
  return costs;
}

}  // namespace misalloc
