// [HS14]'s Algorithm 1 ("exact" allocation) for one pixel: everything the OpenCL
// kernel (kernels/gridsearch.cl) and its C++ reference (host/alloc/GridSearch.cpp)
// share, so that both compute bit for bit the same sums and rank the weight
// combinations with the same code. Only the loop over samples × combinations is each
// side's own: float16 over 16 combinations in the kernel, plain loops in C++.
//
// The sums over a pixel's samples are running sums: the grid α_l is fixed and a
// sample's g = f/p_α never changes, so each search adds only the samples taken since
// the previous one, and the pixel's summary (PixelSummary) carries over with them.
#include "namespace_check.h"
#ifndef MA_GRIDSEARCH_H
#define MA_GRIDSEARCH_H
#include "fallbacks.h"
#include "fastmath.h"

// Which weight combination Algorithm 1 keeps ([HS14] Alg. 1 line 13).
#define MA_RULE_MAX_ENTROPY 0        // as written: λ_{j,l} closest to uniform by entropy
#define MA_RULE_MIN_COST_VARIANCE 1  // least cost × variance of the multi-sample estimator


// Value q of a pixel's sample i, with `pixelSamples` at the pixel's first value: the
// layout of kernels/stats.h (storedSampleIndex), records of M + 2 rows of 16 pixels.
MA_FN float storedValue(MA_GLOBAL const float* pixelSamples, int techniqueCount, int i, int q) {
  return pixelSamples[(i * (techniqueCount + 2) + q) * 16];
}

// 2^−e for x = m · 2^e, m ∈ [1, 2): x · 2^−e ∈ [1, 2). Exponents are clamped so that
// the result stays a normal float.
MA_FN float inversePowerOfTwo(float x) {
  int e = (int)((ma_as_uint(x) >> 23) & 0xffu);
  e = e < 1 ? 1 : (e > 253 ? 253 : e);
  return ma_as_float((ma_uint)(254 - e) << 23);
}

// What decides whether a pixel can be searched (pixelFallbacks), gathered one sample at
// a time (summariseSample) and kept from search to search (mergeSummaries): the kernel
// interleaves 16 pixels' samples, so that it reads every cache line of the blocked
// layout once.
typedef struct {
  float count[MA_GRID_MAX_TECHNIQUES];  // m_j
  int nonZero[MA_GRID_MAX_TECHNIQUES];  // technique j's samples with f > 0; 0: silent
  float maxRatio;                       // max_i f_i / Σ_k p_k(x_i)
  // A NaN, infinite or negative f or pdf, f > 0 where every pdf is 0, or a technique
  // index outside 0 … M−1.
  int invalid;
} PixelSummary;

MA_FN PixelSummary emptySummary(void) {
  PixelSummary s;
  for (int j = 0; j < MA_GRID_MAX_TECHNIQUES; ++j) {
    s.count[j] = 0.0f;
    s.nonZero[j] = 0;
  }
  s.maxRatio = 0.0f;
  s.invalid = 0;
  return s;
}

// The summary of the samples of `a` and `b` together.
MA_FN PixelSummary mergeSummaries(PixelSummary a, PixelSummary b) {
  for (int j = 0; j < MA_GRID_MAX_TECHNIQUES; ++j) {
    a.count[j] += b.count[j];
    a.nonZero[j] += b.nonZero[j];
  }
  a.maxRatio = ma_max(a.maxRatio, b.maxRatio);
  a.invalid |= b.invalid;
  return a;
}

MA_FN void summariseSample(PixelSummary* s, MA_GLOBAL const float* pixelSamples, int techniqueCount, int i) {
  float technique = storedValue(pixelSamples, techniqueCount, i, 0);
  float f = storedValue(pixelSamples, techniqueCount, i, 1), pSum = 0.0f;
  int invalid = !(f >= 0.0f && f <= FLT_MAX), drawn = 0;
  MA_UNROLL
  for (int k = 0; k < techniqueCount; ++k) {
    float p = storedValue(pixelSamples, techniqueCount, i, 2 + k);
    invalid |= !(p >= 0.0f && p <= FLT_MAX);
    pSum += p;
  }
  MA_UNROLL
  for (int j = 0; j < techniqueCount; ++j) {
    int t = technique == (float)j;
    drawn |= t;
    s->count[j] += t ? 1.0f : 0.0f;
    s->nonZero[j] += t && f > 0.0f;
  }
  s->invalid |= invalid || !drawn || (f > 0.0f && pSum == 0.0f);
  s->maxRatio = ma_max(s->maxRatio, pSum > 0.0f ? f / pSum : 0.0f);
}

// The scale of g: since p_α ≥ (min_k α_k) Σ_k p_k and scale · max_i f_i/Σ_k p_k < 4
// (2 but where inversePowerOfTwo clamps), every scaled g = scale · f / p_α is below
// 4 / min_k α_k, so float sums of g² cannot overflow. A power of two, so that sums
// taken at one scale convert exactly to the next (sumsRescale).
MA_FN float sampleScale(PixelSummary s) { return s.maxRatio > 0.0f ? inversePowerOfTwo(s.maxRatio) : 1.0f; }

// A pixel keeps running sums once a valid sample has f > 0: until then they are all 0,
// and after an invalid sample it falls back for good.
MA_FN int hasSums(PixelSummary s) { return !s.invalid && s.maxRatio > 0.0f; }

// The factor that takes Σ g from the scale of the samples summarised in `before` to
// `scale` (its square takes Σ g²), or 0 where there are no sums yet. Both scales are
// powers of two and the scale only falls as max_i f_i/Σ_k p_k grows, so the factor is
// a power of two ≤ 1: exact, unless old sums underflow against a sample up to 2^126
// times larger, where they no longer count.
MA_FN float sumsRescale(PixelSummary before, float scale) {
  return hasSums(before) ? scale / sampleScale(before) : 0.0f;
}

// Where Σ g (moment 0) and Σ g² (moment 1) of technique j's samples at combination l
// are kept: per pixel 2M rows of paddedSize floats.
MA_FN size_t runningSumIndex(int pixel, int j, int moment, int l, int techniqueCount, int paddedSize) {
  return (((size_t)pixel * techniqueCount + j) * 2 + moment) * paddedSize + l;
}

// Why a pixel cannot be searched; every reason gives equal weights. A variance
// estimate needs m_j ≥ 2. A technique whose samples all have f = 0 has μ_j = ν_j = 0:
// cost × variance would then favour it for free, and eq. 4.16 has no solution with
// α_j > 0 (Λ_j = c_j V ≥ 0 while Σ_j α_j Λ_j < 0), so the grid cannot be ranked.
MA_FN ma_uint pixelFallbacks(int techniqueCount, PixelSummary s) {
  if (s.invalid) return MA_FALLBACK_NON_FINITE;
  ma_uint bits = 0;
  int signal = 0;
  for (int j = 0; j < techniqueCount; ++j) {
    bits |= s.count[j] < 2.0f ? MA_FALLBACK_TOO_FEW_SAMPLES : 0u;
    signal |= s.nonZero[j] > 0;
  }
  if (bits != 0) return bits;
  if (!signal) return MA_FALLBACK_NO_SIGNAL;
  for (int j = 0; j < techniqueCount; ++j) bits |= s.nonZero[j] > 0 ? 0u : MA_FALLBACK_SILENT_TECHNIQUE;
  return bits;
}

// The sums need only the samples with f > 0 (the others add 0), and read them grouped
// by technique, so that the loop over one technique's samples runs without tests:
// technique j's start after those of the techniques before it.
MA_FN int preparedFirst(PixelSummary s, int j) {
  int first = 0;
  for (int k = 0; k < j; ++k) first += s.nonZero[k];
  return first;
}

// Copies sample i, if f > 0, to slot next[j]++ of `prepared` (M + 1 floats a slot,
// next[j] starting at preparedFirst): f · scale · 2^−e, then p_k · 2^−e for every k,
// with 2^−e = inversePowerOfTwo(Σ_k p_k). The common power of two leaves every
// g = f/p_α exactly as it was and puts p_α in [min α, 2), so that a product of a few
// p_α neither overflows nor underflows (MA_BATCH_QUOTIENTS).
MA_FN void prepareSample(MA_GLOBAL const float* pixelSamples, int techniqueCount, int i, float scale, int* next,
                         MA_GLOBAL float* prepared) {
  float technique = storedValue(pixelSamples, techniqueCount, i, 0);
  float f = storedValue(pixelSamples, techniqueCount, i, 1);
  if (f == 0.0f) return;
  int j = (int)technique;
  MA_GLOBAL float* out = prepared + (next[j]++) * (techniqueCount + 1);
  float pdf[MA_GRID_MAX_TECHNIQUES], pSum = 0.0f;
  MA_UNROLL
  for (int k = 0; k < techniqueCount; ++k) {
    pdf[k] = storedValue(pixelSamples, techniqueCount, i, 2 + k);
    pSum += pdf[k];
  }
  float normalise = inversePowerOfTwo(pSum);
  out[0] = f * scale * normalise;
  MA_UNROLL
  for (int k = 0; k < techniqueCount; ++k) out[1 + k] = pdf[k] * normalise;
}

// r_c = numerator / x_c for c < count with one division (Montgomery's batch
// inversion): prefix products P_c = x_0 ⋯ x_c, then q = numerator / P_{count−1} and,
// walking back, r_c = q · P_{c−1}, q ← q · x_c, r_0 = q. Each r_c carries about
// count + 1 roundings instead of one. A macro so that the kernel (T = float16) and the
// reference (T = float) run the same operations in the same order; count is a constant.
#define MA_BATCH_QUOTIENTS(T, count, numerator, x, r)                                     \
  do {                                                                                    \
    T prefix_[count];                                                                     \
    prefix_[0] = (x)[0];                                                                  \
    MA_UNROLL for (int c_ = 1; c_ < count; ++c_) prefix_[c_] = prefix_[c_ - 1] * (x)[c_]; \
    T q_ = (numerator) / prefix_[count - 1];                                              \
    MA_UNROLL for (int c_ = count - 1; c_ > 0; --c_) {                                    \
      (r)[c_] = q_ * prefix_[c_ - 1];                                                     \
      q_ = q_ * (x)[c_];                                                                  \
    }                                                                                     \
    (r)[0] = q_;                                                                          \
  } while (0)

// Rule (b): −(Σ_k c_k α_k) V, with V the variance of the multi-sample balance heuristic
// for N = 1 ([SHS16] eq. 21 and Table 2; docs/papers.md), the
// estimator the renderer runs with the selected α: V = ∫ f²/p_α − Σ_j μ'_j²/α_j with
// μ'_j = ∫ α_j p_j f / p_α = α_j μ_j, and ∫ f²/p_α = Σ_j α_j ν_j, so V = Σ_j α_j (ν_j − μ_j²),
// μ_j = E_j[g] and ν_j = E_j[g²] under technique j's pdf, g = f/p_α. They are estimated
// from technique j's m_j samples by [HS14] eq. 6.6 and 6.8. Cancellation can leave a
// tiny negative ν_j − μ_j², which is 0.
// Defined for T = float and, in the kernel, T = float16 (16 combinations at once):
// OpenCL C has no overloading, and the builtins in the body take either.
#define MA_DEFINE_COST_VARIANCE_SCORE(name, T)                                                                         \
  MA_FN T name(int techniqueCount, const T* alpha, T meanCost, const T* sumG, const T* sumG2, const float* invCount) { \
    T variance = 0.0f;                                                                                                 \
    for (int j = 0; j < techniqueCount; ++j) {                                                                         \
      T mu = sumG[j] * invCount[j], nu = sumG2[j] * invCount[j];                                                       \
      variance = ma_fma(alpha[j], ma_max(ma_fma(-mu, mu, nu), 0.0f), variance);                                        \
    }                                                                                                                  \
    return -(meanCost * variance);                                                                                     \
  }
MA_DEFINE_COST_VARIANCE_SCORE(costVarianceScore, float)
#ifdef __OPENCL_VERSION__
MA_DEFINE_COST_VARIANCE_SCORE(costVarianceScore16, float16)
#endif

// Rule (a), [HS14] Alg. 1 lines 9–13. With μ = Σ_j α_j μ_j and the one-sample variance
// V = Σ_j α_j ν_j − μ² ([HS14] eq. 4.4), Λ_j = c_j V − (Σ_k c_k α_k) ν_j ([HS14] eq. 4.16)
// is the same for every j at the optimum. Score: the entropy of λ_j = Λ_j / Σ_j Λ_j.
// Only a λ with every λ_j > 0 is a distribution whose entropy measures the distance
// to uniform; any other (mixed signs, Σ_j Λ_j = 0) scores −∞.
MA_FN float entropyScore(int techniqueCount, const float* alpha, float meanCost, const float* cost, const float* sumG,
                         const float* sumG2, const float* invCount) {
  float mu = 0.0f, secondMoment = 0.0f;
  for (int j = 0; j < techniqueCount; ++j) {
    mu = ma_fma(alpha[j], sumG[j] * invCount[j], mu);
    secondMoment = ma_fma(alpha[j], sumG2[j] * invCount[j], secondMoment);
  }
  float variance = ma_max(ma_fma(-mu, mu, secondMoment), 0.0f);
  float Lambda[MA_GRID_MAX_TECHNIQUES], total = 0.0f;
  for (int j = 0; j < techniqueCount; ++j) {
    Lambda[j] = ma_fma(cost[j], variance, -meanCost * (sumG2[j] * invCount[j]));
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
// the sums of g = f/p_α and g² over each technique's samples and 1/m_j. Larger is better.
MA_FN float gridScore(int rule, int techniqueCount, const float* alpha, float meanCost, const float* cost,
                      const float* sumG, const float* sumG2, const float* invCount) {
  return rule == MA_RULE_MAX_ENTROPY ? entropyScore(techniqueCount, alpha, meanCost, cost, sumG, sumG2, invCount)
                                     : costVarianceScore(techniqueCount, alpha, meanCost, sumG, sumG2, invCount);
}

#endif
