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

// The search's techniques are the stored samples' columns (kernels/stats.h): one per
// technique, or with share columns S > 0 the envmap's pdf under each share of the
// optimal pdf's bank, then the other techniques; below, M counts columns.
//
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
  float maxRatio;                       // max_i f_i / leastPdfSum(x_i)
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

// The least Σ_k p_k over the columns that a combination weighs: all of them, or with
// share columns one share's and the other techniques'. p_α ≥ (min_k α_k) times it, the
// minimum over the columns the combination weighs.
MA_FN float leastPdfSum(int techniqueCount, int shareColumns, const float* pdf) {
  float shareMin = pdf[0], rest = 0.0f;
  MA_UNROLL
  for (int k = 1; k < MA_GRID_MAX_TECHNIQUES; ++k) {
    int used = k < techniqueCount, share = k < shareColumns;
    shareMin = used && share ? ma_min(shareMin, pdf[k]) : shareMin;
    rest += used && !share ? pdf[k] : 0.0f;
  }
  float sum = 0.0f;
  MA_UNROLL
  for (int k = 0; k < MA_GRID_MAX_TECHNIQUES; ++k) sum += k < techniqueCount ? pdf[k] : 0.0f;
  return shareColumns > 0 ? shareMin + rest : sum;
}

MA_FN void summariseSample(PixelSummary* s, MA_GLOBAL const float* pixelSamples, int techniqueCount, int shareColumns,
                           int i) {
  float technique = storedValue(pixelSamples, techniqueCount, i, 0);
  float f = storedValue(pixelSamples, techniqueCount, i, 1), pdf[MA_GRID_MAX_TECHNIQUES];
  int invalid = !(f >= 0.0f && f <= FLT_MAX), drawn = 0;
  MA_UNROLL
  for (int k = 0; k < MA_GRID_MAX_TECHNIQUES; ++k) {
    float p = k < techniqueCount ? storedValue(pixelSamples, techniqueCount, i, 2 + k) : 0.0f;
    invalid |= !(p >= 0.0f && p <= FLT_MAX);
    pdf[k] = p;
  }
  float least = leastPdfSum(techniqueCount, shareColumns, pdf);
  MA_UNROLL
  for (int j = 0; j < techniqueCount; ++j) {
    int t = technique == (float)j;
    drawn |= t;
    s->count[j] += t ? 1.0f : 0.0f;
    s->nonZero[j] += t && f > 0.0f;
  }
  s->invalid |= invalid || !drawn || (f > 0.0f && least == 0.0f);
  s->maxRatio = ma_max(s->maxRatio, least > 0.0f ? f / least : 0.0f);
}

// The scale of g: since p_α ≥ (min_k α_k) leastPdfSum and scale · max_i f_i/leastPdfSum < 4
// (2 but where inversePowerOfTwo clamps), every scaled g = scale · f / p_α is below
// 4 / min_k α_k, so float sums of g² cannot overflow. A power of two, so that sums
// taken at one scale convert exactly to the next (sumsRescale).
MA_FN float sampleScale(PixelSummary s) { return s.maxRatio > 0.0f ? inversePowerOfTwo(s.maxRatio) : 1.0f; }

// With optimal weights ([Kon19], docs/methods.md) rule (b) also sums, over every sample,
// f = 0 included, P_ik = Σ_x p_i p_k / (p_α q) (i ≤ k): n Ã_ik at the combination α
// (optimalVarianceScore). `everySample` (MA_GRID_OPTIMAL_WEIGHTS in the kernel) says so.
//
// A pixel keeps running sums once a valid sample has f > 0 (with optimal weights, once
// it has a valid sample): until then they are all 0, and after an invalid sample it
// falls back for good.
MA_FN int hasSums(PixelSummary s, int everySample) {
  float n = 0.0f;
  for (int k = 0; k < MA_GRID_MAX_TECHNIQUES; ++k) n += s.count[k];
  return !s.invalid && (s.maxRatio > 0.0f || (everySample && n > 0.0f));
}

// The factor that takes Σ g from the scale of the samples summarised in `before` to
// `scale` (its square takes Σ g²), or 0 where there are no sums yet. Both scales are
// powers of two and the scale only falls as max_i f_i/Σ_k p_k grows, so the factor is
// a power of two ≤ 1: exact, unless old sums underflow against a sample up to 2^126
// times larger, where they no longer count.
// P has no scale (it holds no f) and is never rescaled.
MA_FN float sumsRescale(PixelSummary before, float scale, int everySample) {
  return hasSums(before, everySample) ? scale / sampleScale(before) : 0.0f;
}

// The pairs i ≤ k of P, row by row: P's upper triangle.
#define MA_PAIRS(techniqueCount) ((techniqueCount) * ((techniqueCount) + 1) / 2)
MA_FN int pairIndex(int i, int k, int techniqueCount) { return i * techniqueCount - i * (i - 1) / 2 + (k - i); }

// A pixel's rows of paddedSize floats: Σ g (moment 0) and Σ g² (moment 1) of each
// technique j's samples at every combination l, then with optimal weights P's pairs.
MA_FN int sumRows(int techniqueCount, int everySample) {
  return 2 * techniqueCount + (everySample ? MA_PAIRS(techniqueCount) : 0);
}
MA_FN size_t pixelSumsFirst(int pixel, int rows, int paddedSize) { return (size_t)pixel * rows * paddedSize; }
MA_FN size_t runningSumIndex(int j, int moment, int l, int paddedSize) {
  return ((size_t)j * 2 + moment) * paddedSize + l;
}
MA_FN size_t pairSumIndex(int pair, int l, int techniqueCount, int paddedSize) {
  return ((size_t)2 * techniqueCount + pair) * paddedSize + l;
}

// All samples of a pixel so far: the n of rule (b).
MA_FN float sampleCount(int techniqueCount, PixelSummary s) {
  float n = 0.0f;
  for (int k = 0; k < techniqueCount; ++k) n += s.count[k];
  return n;
}

// Why a pixel cannot be searched; every reason gives equal weights. Rule (a) estimates
// each technique's moments from its own samples: that needs m_j ≥ 2, and a technique
// whose samples all have f = 0 has μ_j = ν_j = 0, which eq. 4.16 cannot rank (Λ_j =
// c_j V ≥ 0 while Σ_j α_j Λ_j < 0). Rule (b) estimates V from all n samples at once
// (costVarianceScore): it needs n ≥ 2 and some f > 0, and a silent technique only
// tells it that α_j buys little.
MA_FN ma_uint pixelFallbacks(int techniqueCount, PixelSummary s, int rule) {
  if (s.invalid) return MA_FALLBACK_NON_FINITE;
  ma_uint bits = 0;
  int signal = 0;
  for (int j = 0; j < techniqueCount; ++j) {
    bits |= rule == MA_RULE_MAX_ENTROPY && s.count[j] < 2.0f ? MA_FALLBACK_TOO_FEW_SAMPLES : 0u;
    signal |= s.nonZero[j] > 0;
  }
  if (rule != MA_RULE_MAX_ENTROPY && sampleCount(techniqueCount, s) < 2.0f) bits |= MA_FALLBACK_TOO_FEW_SAMPLES;
  if (bits != 0) return bits;
  if (!signal) return MA_FALLBACK_NO_SIGNAL;
  if (rule != MA_RULE_MAX_ENTROPY) return 0u;
  for (int j = 0; j < techniqueCount; ++j) bits |= s.nonZero[j] > 0 ? 0u : MA_FALLBACK_SILENT_TECHNIQUE;
  return bits;
}

// The sums need only the samples with f > 0 (the others add 0; with optimal weights P
// needs them all), and read them grouped by technique, so that the loop over one
// technique's samples runs without tests: technique j's start after those of the
// techniques before it.
MA_FN int preparedCount(PixelSummary s, int j, int everySample) { return everySample ? (int)s.count[j] : s.nonZero[j]; }
MA_FN int preparedFirst(PixelSummary s, int j, int everySample) {
  int first = 0;
  for (int k = 0; k < j; ++k) first += preparedCount(s, k, everySample);
  return first;
}

// Copies sample i, if f > 0 or `everySample`, to slot next[j]++ of `prepared` (M + 1 floats a slot,
// next[j] starting at preparedFirst): f · scale · 2^−e, then p_k · 2^−e for every k,
// with 2^−e = inversePowerOfTwo(Σ_k p_k). The common power of two leaves every
// g = f/p_α exactly as it was and puts p_α in [min α, 2), so that a product of a few
// p_α neither overflows nor underflows (MA_BATCH_QUOTIENTS).
MA_FN void prepareSample(MA_GLOBAL const float* pixelSamples, int techniqueCount, int i, float scale, int everySample,
                         int* next, MA_GLOBAL float* prepared) {
  float technique = storedValue(pixelSamples, techniqueCount, i, 0);
  float f = storedValue(pixelSamples, techniqueCount, i, 1);
  if (f == 0.0f && !everySample) return;
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
// for N = 1 ([SHS16] eq. 21 and Table 2), the estimator the renderer runs with the
// selected α: V = ∫ f²/p_α − Σ_j α_j μ_j², μ_j = ∫ p_j f / p_α. Both integrals are
// estimated from all n samples of the pixel at once, as a deterministic mixture: a
// sample x_i of a batch whose technique counts are m_k was drawn from
// q = Σ_k (m_k/m) p_k in the balance heuristic's sense, so Σ_i h(x_i)/q(x_i) estimates
// n ∫ h whatever the allocation (docs/papers.md, [HS14] eq. 4.1–4.3). With g = f/p_α,
// w = f/q and r_j = p_j/q: S2 = Σ_i g w estimates n ∫ f²/p_α and M_j = Σ_i g r_j estimates
// n μ_j. Estimating every α from the same samples keeps the differences between
// combinations free of the noise of separate per-technique estimates: two techniques
// with the same pdf give exactly the same V for every α. Cancellation can leave a tiny
// negative V, which is 0.
// Defined for T = float and, in the kernel, T = float16 (16 combinations at once):
// OpenCL C has no overloading, and the builtins in the body take either.
#define MA_DEFINE_COST_VARIANCE_SCORE(name, T)                                                           \
  MA_FN T name(int techniqueCount, const T* alpha, T meanCost, const T* sumM, T sumS2, float invCount) { \
    T muTerm = 0.0f;                                                                                     \
    for (int j = 0; j < techniqueCount; ++j) {                                                           \
      T mu = sumM[j] * invCount;                                                                         \
      muTerm = ma_fma(alpha[j] * mu, mu, muTerm);                                                        \
    }                                                                                                    \
    return -(meanCost * ma_max(ma_fma(sumS2, (T)invCount, -muTerm), 0.0f));                              \
  }
MA_DEFINE_COST_VARIANCE_SCORE(costVarianceScore, float)
#ifdef __OPENCL_VERSION__
MA_DEFINE_COST_VARIANCE_SCORE(costVarianceScore16, float16)
#endif

// Rule (b) with optimal weights: −(Σ_k c_k α_k) V_opt, V_opt = ∫ f²/p_α − b̃ᵀÃ⁻¹b̃ the
// variance of the estimator with [Kon19]'s optimal weights at these counts, N = 1
// (docs/methods.md; host/paper/OptimalWeightsVariance.h checks it by quadrature). With
// the deterministic-mixture sums of costVarianceScore, b̃_j = M_j/n and Ã = P/n, so
// V_opt = (S2 − Mᵀ P⁻¹ M)/n: Mᵀ P⁻¹ M by P's LDLᵀ and forward substitution. Each pivot
// is kept at least MA_PIVOT_FLOOR of its diagonal: a P singular at float precision then
// leaves its near-null direction out of the sum, which can only raise V_opt towards the
// balance heuristic's. The sums are those of one pixel, M unknowns fitted to its own n
// samples: V_opt is then low by about M/n of itself for every α alike, and the pooled
// selection (PooledSelection) compares them summed over the window. Defined for T = float
// and, in the kernel, T = float16.
#define MA_PIVOT_FLOOR 1e-4f
#define MA_DEFINE_OPTIMAL_VARIANCE_SCORE(name, T)                                                              \
  MA_FN T name(int techniqueCount, T meanCost, const T* sumM, T sumS2, const T* sumP, float invCount) {        \
    T L[MA_GRID_MAX_TECHNIQUES][MA_GRID_MAX_TECHNIQUES], d[MA_GRID_MAX_TECHNIQUES], y[MA_GRID_MAX_TECHNIQUES]; \
    T quadratic = 0.0f;                                                                                        \
    for (int i = 0; i < techniqueCount; ++i) {                                                                 \
      T diagonal = sumP[pairIndex(i, i, techniqueCount)], pivot = diagonal, yi = sumM[i];                      \
      for (int k = 0; k < i; ++k) {                                                                            \
        pivot = ma_fma(-L[i][k] * d[k], L[i][k], pivot);                                                       \
        yi = ma_fma(-L[i][k], y[k], yi);                                                                       \
      }                                                                                                        \
      d[i] = ma_max(pivot, MA_PIVOT_FLOOR * diagonal);                                                         \
      y[i] = yi;                                                                                               \
      quadratic = ma_fma(yi / d[i], yi, quadratic);                                                            \
      for (int j = i + 1; j < techniqueCount; ++j) {                                                           \
        T lji = sumP[pairIndex(i, j, techniqueCount)];                                                         \
        for (int k = 0; k < i; ++k) lji = ma_fma(-L[j][k] * d[k], L[i][k], lji);                               \
        L[j][i] = lji / d[i];                                                                                  \
      }                                                                                                        \
    }                                                                                                          \
    return -(meanCost * ma_max((sumS2 - quadratic) * invCount, 0.0f));                                         \
  }
MA_DEFINE_OPTIMAL_VARIANCE_SCORE(optimalVarianceScore, float)
#ifdef __OPENCL_VERSION__
MA_DEFINE_OPTIMAL_VARIANCE_SCORE(optimalVarianceScore16, float16)
#endif

// The mixture weights of a batch of new samples: r_j = p_j/q and w = f/q with
// q = Σ_k (m_k/m) p_k (rule (b) above), from a prepared sample x (prepareSample). A
// common power of two in x leaves both as they are.
MA_FN float mixtureWeights(int techniqueCount, const float* stageMix, MA_GLOBAL const float* x, float* r) {
  float q = 0.0f;
  for (int k = 0; k < techniqueCount; ++k) q = ma_fma(stageMix[k], x[1 + k], q);
  float invQ = q > 0.0f ? 1.0f / q : 0.0f;
  for (int k = 0; k < techniqueCount; ++k) r[k] = x[1 + k] * invQ;
  return x[0] * invQ;
}

// The technique fractions m_k/m of a batch of new samples, summarised in `added`.
MA_FN void stageMixture(int techniqueCount, PixelSummary added, float* stageMix) {
  float m = 0.0f;
  for (int k = 0; k < techniqueCount; ++k) m += added.count[k];
  for (int k = 0; k < techniqueCount; ++k) stageMix[k] = m > 0.0f ? added.count[k] / m : 0.0f;
}

// Rule (a), [HS14] Alg. 1 lines 9–13. With μ = Σ_j α_j μ_j and the one-sample variance
// V = Σ_j α_j ν_j − μ² ([HS14] eq. 4.4), Λ_j = c_j V − (Σ_k c_k α_k) ν_j ([HS14] eq. 4.16)
// is the same for every j at the optimum. Score: the entropy of λ_j = Λ_j / Σ_j Λ_j.
// Only a λ with every λ_j > 0 is a distribution whose entropy measures the distance
// to uniform; any other (mixed signs, Σ_j Λ_j = 0) scores −∞.
// Defined for T = float and, in the kernel, T = float16 (16 combinations at once).
#define MA_DEFINE_ENTROPY_SCORE(name, T, logBase2)                                                               \
  MA_FN T name(int techniqueCount, const T* alpha, T meanCost, const float* cost, const T* sumG, const T* sumG2, \
               const float* invCount) {                                                                          \
    T mu = 0.0f, secondMoment = 0.0f;                                                                            \
    for (int j = 0; j < techniqueCount; ++j) {                                                                   \
      mu = ma_fma(alpha[j], sumG[j] * invCount[j], mu);                                                          \
      secondMoment = ma_fma(alpha[j], sumG2[j] * invCount[j], secondMoment);                                     \
    }                                                                                                            \
    T variance = ma_max(ma_fma(-mu, mu, secondMoment), 0.0f);                                                    \
    T Lambda[MA_GRID_MAX_TECHNIQUES], total = 0.0f;                                                              \
    for (int j = 0; j < techniqueCount; ++j) {                                                                   \
      Lambda[j] = ma_fma((T)cost[j], variance, -meanCost * (sumG2[j] * invCount[j]));                            \
      total += Lambda[j];                                                                                        \
    }                                                                                                            \
    T entropy = 0.0f, distribution = 1.0f;                                                                       \
    for (int j = 0; j < techniqueCount; ++j) {                                                                   \
      T lambda = Lambda[j] / total;                                                                              \
      distribution = lambda > 0.0f ? distribution : 0.0f;                                                        \
      entropy = ma_fma(-lambda, logBase2(lambda > 0.0f ? lambda : 1.0f), entropy);                               \
    }                                                                                                            \
    return distribution > 0.0f ? entropy : -INFINITY;                                                            \
  }
MA_DEFINE_ENTROPY_SCORE(entropyScore, float, fastLog2)
#ifdef __OPENCL_VERSION__
MA_DEFINE_ENTROPY_SCORE(entropyScore16, float16, fastLog2x16)
#endif

// The score of weight combination α (cost Σ_k c_k α_k = meanCost) for one pixel, from
// its running sums (runningSumIndex): rule (a) reads Σ g and Σ g² over each technique's
// samples with 1/m_j, rule (b) M_j in technique j's first row and S2 in technique 0's
// second with 1/n. Larger is better.
MA_FN float gridScore(int rule, int techniqueCount, const float* alpha, float meanCost, const float* cost,
                      const float* sumG, const float* sumG2, const float* invCount, float invTotal) {
  return rule == MA_RULE_MAX_ENTROPY ? entropyScore(techniqueCount, alpha, meanCost, cost, sumG, sumG2, invCount)
                                     : costVarianceScore(techniqueCount, alpha, meanCost, sumG, sumG2[0], invTotal);
}

// Pooled selection (host/alloc/Pooling.h says why): a pixel ranks the combinations by
// the sum of its neighbours' scores, each brought from its own scale to the smallest
// scale in the window, so that no factor exceeds 1 and the sum cannot overflow.
MA_FN float poolingFactor(float scaleMin, float scale) {
  float r = scaleMin / scale;
  return r * r;
}

// The window of radius r around pixel (x, y), clipped at the image's edges, over the
// pixels of its surface (host/scene/Surfaces.h). For r > 0 it leaves the pixel itself
// out: its α and its pilot's weight then come from its neighbours' samples only, so
// that the weight is independent of the pilot it weighs (host/alloc/StageWeights.h,
// pilotWeight).
typedef struct {
  int x0, x1, y0, y1;
  int self;     // the pixel left out, −1 for none
  int surface;  // the pixel's surface: only its pixels pool
} PoolWindow;

MA_FN PoolWindow poolWindow(int pixel, int width, int height, int radius, int surface) {
  PoolWindow w;
  int x = pixel % width, y = pixel / width;
  w.x0 = x - radius < 0 ? 0 : x - radius;
  w.x1 = x + radius > width - 1 ? width - 1 : x + radius;
  w.y0 = y - radius < 0 ? 0 : y - radius;
  w.y1 = y + radius > height - 1 ? height - 1 : y + radius;
  w.self = radius > 0 ? pixel : -1;
  w.surface = surface;
  return w;
}

// Whether pixel q of window w, of surface `surface` and with fallback bits `fallback`,
// enters the pooled sums.
MA_FN int pools(PoolWindow w, int q, ma_uint fallback, int surface) {
  return q != w.self && fallback == 0u && surface == w.surface;
}

// V(equal)/V(selected), the variances (not cost × variance) that the pooled scores
// (≤ 0) predict, from those scores and the costs per sample of the two combinations;
// +∞ where the selected one has none. Only for a selection that did not skip, so that
// equal weights have some variance.
MA_FN float pooledVarianceRatio(float best, float bestCost, float equal, float equalCost) {
  float varianceBest = -best / bestCost, varianceEqual = -equal / equalCost;
  return varianceBest > 0.0f ? varianceEqual / varianceBest : INFINITY;
}

// The pixel's own variance (not cost × variance) at a combination, from its own score
// (≤ 0, in the units of its scale: sampleScale), the combination's cost per sample and
// that scale. Where the window left the pixel out, its own samples did not choose the
// combination, so this is a held-out check of the choice: summed over the image, it
// predicts what the allocation gains without the optimism of a selection judged by
// the samples that made it (host/alloc/WholeImageRule.h).
MA_FN float heldOutVariance(float score, float cost, float scale) { return -score / cost / scale / scale; }

// The skip rule, from the pooled scores of the best and the equal combination and the
// sum and sum of squares of the window's `count` per-pixel differences d_q (their
// pooled score at best minus at equal). Scores are −cost × variance ≤ 0, so the
// predicted gain 1 − best / equal reaches minGain where best > (1 − minGain) · equal.
// The selection maximises that gain over noisy estimates, so it must also be
// significant: Σ d_q more than MA_SKIP_Z standard errors above 0, the d_q taken as
// independent draws (a one-sided t-test; a single pixel cannot be tested). Adapting is
// skipped otherwise, also for NaN and where equal weights already have no variance.
// One standard error: a wrong adaptation where V(α) is flat costs little, and a pilot
// of a few samples per pixel rarely shows a real gain at 2 or 3 (docs/results.md,
// "The skip rule's significance").
#define MA_SKIP_Z 1.0f
MA_FN int skipsAdapting(float best, float equal, float minGain, float sumD, float sumD2, float count) {
  if (!(best > (1.0f - minGain) * equal)) return 1;
  if (count < 2.0f) return 0;
  float variance = ma_max((sumD2 - sumD * sumD / count) / (count - 1.0f), 0.0f);
  return !(sumD * sumD > MA_SKIP_Z * MA_SKIP_Z * count * variance);
}

#endif
