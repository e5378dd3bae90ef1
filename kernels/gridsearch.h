// Paper 000's Algorithm 1 ("exact" allocation) for one pixel: the per-pixel decisions
// that the OpenCL kernel (kernels/gridsearch.cl, 16 pixels per work-item) and its C++
// reference (host/alloc/GridSearch.cpp) share, so both rank the weight combinations
// with the same code. The sums over the stored samples are each side's own loop.
#ifndef MA_GRIDSEARCH_H
#define MA_GRIDSEARCH_H
#include "fastmath.h"

#define MA_GRID_MAX_TECHNIQUES 4

// Which weight combination Algorithm 1 keeps (000 Alg. 1 line 13).
#define MA_RULE_MAX_ENTROPY 0        // as written: λ_{j,l} closest to uniform by entropy
#define MA_RULE_MIN_COST_VARIANCE 1  // least cost × variance of the multi-sample estimator

// The bits of host/alloc/Allocation.h's AllocationFallback (static_assert there).
#define MA_FALLBACK_NON_FINITE 1u
#define MA_FALLBACK_TOO_FEW_SAMPLES 2u
#define MA_FALLBACK_NO_SIGNAL 4u
#define MA_FALLBACK_SILENT_TECHNIQUE 8u
#define MA_FALLBACK_SINGULAR_SYSTEM 64u

// Why a pixel's stored samples cannot be searched, from their summary: `invalid` (a
// NaN, infinite or negative f or pdf, f > 0 where every pdf is 0, or a technique index
// outside 0 … M−1), the count m_j and the largest f of each technique. Every reason
// gives equal weights. A variance estimate needs m_j ≥ 2. A technique whose samples
// all have f = 0 has μ_j = ν_j = 0: cost × variance would then favour it for free, and
// eq. 4.16 has no solution with α_j > 0 (Λ_j = c_j V ≥ 0 while Σ_j α_j Λ_j < 0), so
// the grid cannot be ranked.
MA_FN ma_uint pixelFallbacks(int techniqueCount, const float* count, const float* maxF, int invalid) {
  if (invalid) return MA_FALLBACK_NON_FINITE;
  ma_uint bits = 0;
  int signal = 0;
  for (int j = 0; j < techniqueCount; ++j) {
    bits |= count[j] < 2.0f ? MA_FALLBACK_TOO_FEW_SAMPLES : 0u;
    signal |= maxF[j] > 0.0f;
  }
  if (bits != 0) return bits;
  if (!signal) return MA_FALLBACK_NO_SIGNAL;
  for (int j = 0; j < techniqueCount; ++j) bits |= maxF[j] > 0.0f ? 0u : MA_FALLBACK_SILENT_TECHNIQUE;
  return bits;
}

// Rule (b): −(Σ_k c_k α_k) V_multi, with the multi-sample balance-heuristic variance for
// N = 1 (002 eq. 21, Table 2: V = Σ_j α_j σ'_j² with σ'_j² the variance of g = f/p_α
// under p_j), estimated with 000 eq. 6.6 and 6.8 from technique j's samples:
// σ'_j² = ν_j − μ_j². Cancellation can leave a tiny negative number, which is 0.
MA_FN float costVarianceScore(int techniqueCount, const float* alpha, float meanCost, const float* sumG,
                              const float* sumG2, const float* count) {
  float variance = 0.0f;
  for (int j = 0; j < techniqueCount; ++j) {
    float mu = sumG[j] / count[j], nu = sumG2[j] / count[j];
    variance = ma_fma(alpha[j], ma_max(ma_fma(-mu, mu, nu), 0.0f), variance);
  }
  return -(meanCost * variance);
}

// Rule (a), 000 Alg. 1 lines 9–13. With μ = Σ_j α_j μ_j and the one-sample variance
// V = Σ_j α_j ν_j − μ² (000 eq. 4.4), Λ_j = c_j V − (Σ_k c_k α_k) ν_j (000 eq. 4.16)
// is the same for every j at the optimum. Score: the entropy of λ_j = Λ_j / Σ_j Λ_j.
// Only a λ with every λ_j > 0 is a distribution whose entropy measures the distance
// to uniform; any other (mixed signs, Σ_j Λ_j = 0) scores −∞.
MA_FN float entropyScore(int techniqueCount, const float* alpha, float meanCost, const float* cost,
                         const float* sumG, const float* sumG2, const float* count) {
  float mu = 0.0f, secondMoment = 0.0f;
  for (int j = 0; j < techniqueCount; ++j) {
    mu = ma_fma(alpha[j], sumG[j] / count[j], mu);
    secondMoment = ma_fma(alpha[j], sumG2[j] / count[j], secondMoment);
  }
  float variance = ma_max(ma_fma(-mu, mu, secondMoment), 0.0f);
  float Lambda[MA_GRID_MAX_TECHNIQUES], total = 0.0f;
  for (int j = 0; j < techniqueCount; ++j) {
    Lambda[j] = ma_fma(cost[j], variance, -meanCost * (sumG2[j] / count[j]));
    total += Lambda[j];
  }
  float entropy = 0.0f;
  int distribution = 1;
  for (int j = 0; j < techniqueCount; ++j) {
    float lambda = Lambda[j] / total;
    distribution &= lambda > 0.0f;
    entropy = ma_fma(-lambda, fastLog2(lambda > 0.0f ? lambda : 1.0f), entropy);
  }
  return distribution ? entropy : -INFINITY;
}

// The score of weight combination α (cost Σ_k c_k α_k = meanCost) for one pixel, from
// the sums of g = f/p_α and g² over each technique's samples. Larger is better.
MA_FN float gridScore(int rule, int techniqueCount, const float* alpha, float meanCost, const float* cost,
                      const float* sumG, const float* sumG2, const float* count) {
  return rule == MA_RULE_MAX_ENTROPY ? entropyScore(techniqueCount, alpha, meanCost, cost, sumG, sumG2, count)
                                     : costVarianceScore(techniqueCount, alpha, meanCost, sumG, sumG2, count);
}

#endif
