#pragma once
// Every allocation rule of host/alloc run on a 1D example by sampling: pilot samples
// from each technique feed PixelSamples::add, exactly as a pixel's samples would, the
// rule turns them into weights, and quadrature gives the exact variance those weights
// achieve.

#include <cstdint>
#include <string>
#include <vector>

#include "paper/Example1D.h"

namespace misalloc {

enum class AllocationRule {
  Equal,                    // α = 1/M
  Heuristic,                // [HS14] eq. 4.20
  SigmaSqrtC,               // [SHS16] eq. 31
  LinearDropMostNegative,   // [SS23] eq. 14, Sec. 5.1 first technique
  LinearMinSampleVariance,  // [SS23] eq. 14, Sec. 5.1 second technique
};

std::vector<AllocationRule> allAllocationRules();
std::string allocationRuleName(AllocationRule rule);

struct StudyConfig {
  int runs = 200;
  int samplesPerTechnique = 100;
  std::uint64_t seed = 1;
};

struct Quantiles {
  double mean, median, p10, p90;  // p10/p90 interpolate linearly between order statistics
};

struct RuleOutcome {
  AllocationRule rule;
  std::vector<double> meanAlpha;
  // Over the runs: (Σ_k c_k α_k)·V(α) with the example's costs and V the exact N = 1
  // variance of the estimator the rule allocates for: [SHS16] eq. 29 (count-independent
  // weights) for SigmaSqrtC, the multi-sample balance heuristic ([SHS16] eq. 21) otherwise.
  Quantiles inefficiency;
  int fallbackRuns;  // runs in which the rule used a fallback
  int boundaryRuns;  // runs in which [SS23] Sec. 5.1 set a weight to 0
};

// Throws std::domain_error if a technique's "density" cannot be sampled ([HS14] App. C).
std::vector<RuleOutcome> runAllocationStudy(const Example1D& example, const StudyConfig& config);

}  // namespace misalloc
