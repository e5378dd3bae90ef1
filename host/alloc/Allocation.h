#pragma once
// The result every allocation rule returns, and what the rules share: equal weights,
// cost validation and the checks that decide whether a pixel's sums can be used.

#include <optional>
#include <vector>

#include "alloc/PixelStats.h"

namespace misalloc {

// Why an allocation departed from its formula. Bits, so one pixel can report several.
enum AllocationFallback : unsigned {
  kFallbackNone = 0,
  kFallbackNonFinite = 1u << 0,         // NaN or ∞ in the sums: equal weights
  kFallbackTooFewSamples = 1u << 1,     // a technique has fewer samples than the estimate needs: equal weights
  kFallbackNoSignal = 1u << 2,          // every sample of the pixel has f = 0: equal weights
  kFallbackSilentTechnique = 1u << 3,   // a technique saw only f = 0: its weight is 0
  kFallbackZeroVariance = 1u << 4,      // a variance estimate is 0: the formula's limit is used
  kFallbackInfiniteVariance = 1u << 5,  // every technique's variance is infinite: equal weights
  kFallbackSingularSystem = 1u << 6,    // [SS23] eq. 14 has no unique solution: equal weights over the active set
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
