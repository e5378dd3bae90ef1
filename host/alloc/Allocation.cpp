#include "alloc/Allocation.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace misalloc {

Allocation allocateEqual(int techniqueCount) {
  return Allocation{std::vector<double>(techniqueCount, 1.0 / techniqueCount)};
}

Allocation equalFallback(int techniqueCount, unsigned reason) {
  Allocation a = allocateEqual(techniqueCount);
  a.fallbacks = reason;
  return a;
}

void validateCosts(const std::vector<double>& costs, int techniqueCount) {
  if (static_cast<int>(costs.size()) != techniqueCount)
    throw std::invalid_argument("sampling costs: expected " + std::to_string(techniqueCount) +
                                " costs (one per technique), got " + std::to_string(costs.size()));
  for (std::size_t k = 0; k < costs.size(); ++k)
    if (!(std::isfinite(costs[k]) && costs[k] > 0))
      throw std::invalid_argument("sampling costs: cost of technique " + std::to_string(k) + " is " +
                                  std::to_string(costs[k]) + "; every cost must be finite and > 0");
}

// A method keeps only some of the sums (kernels/stats.h); the others stay 0. Any kept
// one is positive once a single sample has f ≠ 0.
bool isSilent(const TechniqueStats& t) { return t.sumW2 == 0 && t.sumBalance2 == 0 && t.sumF == 0; }

std::optional<Allocation> unusableStatsFallback(const PixelStats& stats, double minSamples) {
  int m = stats.techniqueCount;
  if (!stats.isFinite()) return equalFallback(m, kFallbackNonFinite);
  bool anySignal = false;
  for (int k = 0; k < m; ++k) {
    if (stats.technique[k].count < minSamples) return equalFallback(m, kFallbackTooFewSamples);
    anySignal = anySignal || !isSilent(stats.technique[k]);
  }
  if (!anySignal) return equalFallback(m, kFallbackNoSignal);
  return std::nullopt;
}

}  // namespace misalloc
