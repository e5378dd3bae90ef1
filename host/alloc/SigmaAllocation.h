#pragma once
// Sample counts for the estimator with count-independent weights ([SHS16] Sec. 4).

#include <vector>

#include "alloc/Allocation.h"

namespace misalloc {

// [SHS16] eq. 31 (Theorem 3, eq. 14): n_i ∝ σ_i / √c_i minimises cost × variance of the
// estimator of [SHS16] eq. 26, whose per-technique variances σ_i² ([SHS16] eq. 28) do not
// depend on the counts. If every σ_i = 0 any allocation has zero variance; weights
// are then equal (kFallbackZeroVariance), which keeps every technique sampled.
// Throws std::invalid_argument on a negative or non-finite σ_i or an invalid cost.
Allocation sigmaSqrtCWeights(const std::vector<double>& sigmas, const std::vector<double>& costs);

// The same with σ_i² estimated as the sample variance of f/Σ_l p_l over technique i's
// samples ([SHS16] eq. 27, 28; [HS14] eq. 6.19). Needs n_i ≥ 2. A silent technique gets
// σ_i = 0 and so no further samples (flagged kFallbackSilentTechnique). Note that
// eq. 26 stays unbiased only while every technique has at least one sample in total,
// which the pilot stage guarantees.
Allocation allocateSigmaSqrtC(const PixelStats& stats, const std::vector<double>& costs);
Allocation allocateSigmaSqrtC(const PixelStats& stats);

}  // namespace misalloc
