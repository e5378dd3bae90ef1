#include "alloc/WholeImageRule.h"

#include <cmath>

namespace misalloc {

std::optional<double> predictedImageGain(const StageAllocation& next, const std::vector<double>& costs,
                                         const std::vector<unsigned char>& covered) {
  if (next.heldOutVariance.empty()) return std::nullopt;
  const int M = int(costs.size());
  double equalCostPerSample = 0;
  for (int k = 0; k < M; ++k) equalCostPerSample += costs[k] / M;
  double varianceEqual = 0, varianceAlpha = 0, costEqual = 0, costAlpha = 0;
  bool predicted = false;
  for (size_t p = 0; p < covered.size(); ++p) {
    if (!covered[p]) continue;
    const double equal = next.heldOutVariance[2 * p], alpha = next.heldOutVariance[2 * p + 1];
    if (std::isfinite(equal) && std::isfinite(alpha)) varianceEqual += equal, varianceAlpha += alpha, predicted = true;
    for (int k = 0; k < M; ++k) costAlpha += costs[k] * next.allocations[p].alpha[k];
    costEqual += equalCostPerSample;
  }
  if (!predicted) return std::nullopt;
  if (!(varianceEqual > 0)) return 1.0;
  return (varianceEqual * costEqual) / (varianceAlpha * costAlpha);
}

bool keepsEqualCounts(const std::optional<double>& predictedGain, double gainBelow) {
  return predictedGain && *predictedGain < gainBelow;
}

StageAllocation equalStageAllocation(int pixels, int techniqueCount) {
  return {std::vector<Allocation>(pixels, allocateEqual(techniqueCount)),
          std::vector<float>(pixels, 1.0f),
          std::vector<unsigned char>(pixels, 1),
          {}};
}

}  // namespace misalloc
