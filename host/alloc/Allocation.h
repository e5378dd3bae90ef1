#pragma once
// The result every allocation rule returns, and what the rules share: equal weights,
// cost validation and the checks that decide whether a pixel's sums can be used.

#include <optional>
#include <vector>

#include "stats/PixelStats.h"

namespace misalloc {

namespace kern {
#include "fallbacks.h"
}  // namespace kern

// Why an allocation departed from its formula. Bits, so one pixel can report several;
// their meanings are in kernels/fallbacks.h, shared with the grid-search kernel.
enum AllocationFallback : unsigned {
  kFallbackNone = 0,
  kFallbackNonFinite = MA_FALLBACK_NON_FINITE,
  kFallbackTooFewSamples = MA_FALLBACK_TOO_FEW_SAMPLES,
  kFallbackNoSignal = MA_FALLBACK_NO_SIGNAL,
  kFallbackSilentTechnique = MA_FALLBACK_SILENT_TECHNIQUE,
  kFallbackZeroVariance = MA_FALLBACK_ZERO_VARIANCE,
  kFallbackInfiniteVariance = MA_FALLBACK_INFINITE_VARIANCE,
  kFallbackSingularSystem = MA_FALLBACK_SINGULAR_SYSTEM,
};

struct Allocation {
  std::vector<double> alpha;  // α_k ≥ 0, Σ α_k = 1
  unsigned fallbacks = kFallbackNone;
  // Weights the linear heuristic set to 0 by [SS23] Sec. 5.1. Part of that rule, not a
  // fallback; counted because a negative raw solution flags a boundary optimum.
  int zeroedWeights = 0;

  bool usedFallback() const { return fallbacks != kFallbackNone; }
};

// α_k = 1/M: Veach's equal sample budgets, the baseline of all three papers.
Allocation allocateEqual(int techniqueCount);

// Equal weights, recording why the rule could not be applied.
Allocation equalFallback(int techniqueCount, unsigned reason);

// Throws std::invalid_argument unless there is exactly one finite cost c_k > 0 per
// technique: a zero or negative cost makes "cost × variance" meaningless.
void validateCosts(const std::vector<double>& costs, int techniqueCount);

// The fallback for sums no rule can use: non-finite sums, a technique with fewer than
// minSamples samples, or a pixel whose samples are all zero. nullopt if usable.
std::optional<Allocation> unusableStatsFallback(const PixelStats& stats, double minSamples);

// A technique whose samples all have f = 0 carries no information about f.
bool isSilent(const TechniqueStats& t);

}  // namespace misalloc
