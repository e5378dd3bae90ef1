#pragma once
// How a render's stages are combined into one estimate: each stage is an independent
// unbiased estimate with its own counts, weighted by its estimated variance.

#include "sampling/Stage.h"

namespace misalloc {

// Estimated variance of a pixel's stage estimate from the per-technique moments of
// its luminance values w. Balance heuristic, multi-sample: Σ_k n_k s_k² / N² ([SHS16] eq. 21
// with estimated σ_k); one-sample: s² / N over all samples ([SHS16] Table 2);
// count-independent weights: Σ_k s_k² / n_k ([SHS16] eq. 28).
double stageVariance(const StagePlan& plan, const StageResult& result, int pixel, Estimator estimator);

// The pilot's weight in the estimate. The stages are independent unbiased estimates,
// best combined with weights ∝ N_b/V_b (inverse-variance weighting, V_b/N_b a stage's
// variance as [SHS16] eq. 21 gives it). The pilot took N_0 samples at equal counts and
// the stages after it N − N_0 at α, so with r = V(equal)/V(α) that is
// N_0 / (N_0 + (N − N_0) r): N_0/N for r = 1, less where α beats equal counts. The
// estimate stays unbiased because r comes from the pixel's neighbours, not from the
// pilot it weighs, and is fixed before the stages after it (PooledSelection). A NaN
// ratio counts as 1.
double pilotWeight(float varianceRatio, int pilotSamples, int spp);

}  // namespace misalloc
