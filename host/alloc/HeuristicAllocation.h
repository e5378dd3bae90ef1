#pragma once
// Havran & Sbert's inverse-variance heuristic ([HS14] Sec. 4.3).

#include <vector>

#include "alloc/Allocation.h"

namespace misalloc {

// H({x_k}) = M / Σ_k 1/x_k; a term x_k = +∞ contributes 0 to the sum.
double harmonicMean(const std::vector<double>& values);

// [HS14] eq. 4.20 (eq. 4.17 for equal costs): α_k = H({c_l V_l}) / (M c_k V_k), with V_k
// the variance of technique k's own estimator ([HS14] eq. 4.18) and c_k its cost.
// Limits from [HS14] Sec. 4.3: V_k = +∞ gives α_k = 0; if some V_k = 0 those techniques
// share all the weight in proportion to 1/c_k (kFallbackZeroVariance). If every V_k is
// infinite, weights are equal (kFallbackInfiniteVariance). Throws
// std::invalid_argument on a negative or NaN variance or an invalid cost.
Allocation heuristicWeights(const std::vector<double>& variances, const std::vector<double>& costs);

// The same with V_k estimated from the samples of technique k (sample variance of
// w = f/p_k, [HS14] eq. 6.19). Needs n_k ≥ 2. A silent technique (all f = 0) while others
// see f ≠ 0 gets V_k = ∞: its estimator keeps returning 0 for a nonzero integral.
Allocation allocateHeuristic(const PixelStats& stats, const std::vector<double>& costs);
Allocation allocateHeuristic(const PixelStats& stats);

}  // namespace misalloc
