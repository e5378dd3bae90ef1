// [HS14] Algorithm 1, lines 5–13, for every pixel at once: one work-item per block of 16
// pixels adds the samples that kernels/sample.cl stored since the previous search
// (kernels/stats.h, storedSampleIndex) to the pixel's running sums for the U weight
// combinations, 16 of them per float16, and selects from the sums. Host side and C++
// reference: host/alloc/GridSearch.h. What both share: kernels/gridsearch.h.
//
// Compile-time options (GridSearch's constructor): MA_TECHNIQUES (M, the stored
// samples' columns), MA_SHARE_COLUMNS (S, kernels/stats.h), MA_GRID_VECTORS (B), the
// float16s of combinations summed in one pass over the samples, and
// MA_GRID_OPTIMAL_WEIGHTS: rule (b) ranks by the variance with [Kon19]'s optimal weights
// (optimalVarianceScore), from the sums P over every sample besides S2 and M_j.
//
// Shape (docs/pocl.md): explicit float16 arithmetic is what
// reaches 512-bit code on PoCL. Lanes are combinations, not pixels, so a sample's
// technique is the same in every lane: its sums need no masks, and a pixel's samples,
// copied once grouped by technique, are read without tests. A division has the same
// throughput per lane at 512 and 256 bits, so the B quotients f/p_α of one sample
// share one (MA_BATCH_QUOTIENTS), leaving multiplies, and 2B independent accumulator
// chains. Sums are float: the scaling keeps g < 4/min α, and summing a few hundred
// samples in order loses ~√n ulps, far below the sampling noise of the estimates;
// carried from search to search, they are the same sums in the same order.
//
// -Wpsabi: on an x86 CPU without AVX-512 (PoCL compiles for the CPU it runs on), clang
// warns at each call that passes or returns a float16 or int16 by value, the builtins'
// included (vload16, vstore16, fma, select, fmax): 28 warnings, printed by PoCL as
// "28 warnings generated." on the program's first build. The warning is about linking
// code compiled with and without AVX-512, whose calling conventions for 512-bit vectors
// differ; this program has no such boundary: every function here is always_inline, and
// PoCL's builtin library is compiled for the same CPU as the kernel. Passing the vectors
// through memory instead would change the code PoCL generates, so the diagnostic, which
// changes nothing in the code, is what is turned off, for this file only.
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpsabi"
#endif
#include "gridsearch.h"

#define MA_PASS (16 * MA_GRID_VECTORS)  // combinations per pass over the samples
#define MA_EVERY_SAMPLE MA_GRID_OPTIMAL_WEIGHTS
#define MA_PAIR_COUNT MA_PAIRS(MA_TECHNIQUES)

// numerator/p_α of the prepared sample x (prepareSample) for the combinations of the
// pass, alpha[v][k] holding α_k of the 16 combinations of vector v: one division for all
// (MA_BATCH_QUOTIENTS). With numerator f, g = f/p_α.
MA_FN void passQuotients(__global const float* x, const float16 alpha[MA_GRID_VECTORS][MA_TECHNIQUES],
                         float16 numerator, float16* g) {
  float16 p[MA_GRID_VECTORS];
  MA_UNROLL
  for (int v = 0; v < MA_GRID_VECTORS; ++v) {
    p[v] = alpha[v][0] * x[1];
    MA_UNROLL
    for (int k = 1; k < MA_TECHNIQUES; ++k) p[v] = fma(alpha[v][k], (float16)x[1 + k], p[v]);
  }
  MA_BATCH_QUOTIENTS(float16, MA_GRID_VECTORS, numerator, p, g);
}

// Adds g and g² of technique j's n prepared samples (prepareSample) to its sums for the
// combinations l0 … l0 + MA_PASS − 1 ([HS14] Alg. 1 line 8; eq. 6.6 and 6.8 before dividing
// by m_j).
MA_FN void sumTechnique(__global const float* prepared, int n, const float16 alpha[MA_GRID_VECTORS][MA_TECHNIQUES],
                        float16* sumG, float16* sumG2) {
  float16 s[MA_GRID_VECTORS], s2[MA_GRID_VECTORS];
  MA_UNROLL
  for (int v = 0; v < MA_GRID_VECTORS; ++v) {
    s[v] = sumG[v];
    s2[v] = sumG2[v];
  }
  for (int i = 0; i < n; ++i) {
    __global const float* x = prepared + i * (MA_TECHNIQUES + 1);
    float16 g[MA_GRID_VECTORS];
    passQuotients(x, alpha, (float16)x[0], g);
    MA_UNROLL
    for (int v = 0; v < MA_GRID_VECTORS; ++v) {
      s[v] += g[v];
      s2[v] = fma(g[v], g[v], s2[v]);
    }
  }
  MA_UNROLL
  for (int v = 0; v < MA_GRID_VECTORS; ++v) {
    sumG[v] = s[v];
    sumG2[v] = s2[v];
  }
}

// Rule (b)'s sums over the n prepared samples of a batch with technique fractions
// stageMix (kernels/gridsearch.h, costVarianceScore): M_j += g r_j into sumM[j] and
// S2 += g w into sumS2, for the combinations l0 … l0 + MA_PASS − 1. With optimal weights
// also P_ik += (p_i/p_α) r_k into sumP (optimalVarianceScore), from 1/p_α, whose batch
// then gives g = f · (1/p_α) too.
MA_FN void sumMixture(__global const float* prepared, int n, const float16 alpha[MA_GRID_VECTORS][MA_TECHNIQUES],
                      const float* stageMix, float16 sumM[MA_TECHNIQUES][MA_GRID_VECTORS], float16* sumS2,
                      float16 sumP[][MA_GRID_VECTORS]) {
  for (int i = 0; i < n; ++i) {
    __global const float* x = prepared + i * (MA_TECHNIQUES + 1);
    float r[MA_TECHNIQUES];
    float w = mixtureWeights(MA_TECHNIQUES, stageMix, x, r);
    float16 g[MA_GRID_VECTORS];
#if MA_GRID_OPTIMAL_WEIGHTS
    float16 inverse[MA_GRID_VECTORS];
    passQuotients(x, alpha, (float16)1.0f, inverse);
    MA_UNROLL
    for (int v = 0; v < MA_GRID_VECTORS; ++v) {
      g[v] = inverse[v] * x[0];
      int pair = 0;
      MA_UNROLL
      for (int a = 0; a < MA_TECHNIQUES; ++a) {
        float16 t = inverse[v] * x[1 + a];
        MA_UNROLL
        for (int b = a; b < MA_TECHNIQUES; ++b, ++pair) sumP[pair][v] = fma(t, (float16)r[b], sumP[pair][v]);
      }
    }
#else
    passQuotients(x, alpha, (float16)x[0], g);
#endif
    MA_UNROLL
    for (int v = 0; v < MA_GRID_VECTORS; ++v) {
      sumS2[v] = fma(g[v], (float16)w, sumS2[v]);
      MA_UNROLL
      for (int j = 0; j < MA_TECHNIQUES; ++j) sumM[j][v] = fma(g[v], (float16)r[j], sumM[j][v]);
    }
  }
}

// The best of 16 candidates (score, index) per lane: the highest score, ties to the
// lowest index, as a scan in index order would keep it. NaN scores never win, nor do
// the copies that pad the grid: they share a batch of quotients with other
// combinations than the original, so their sums can differ in the last bits.
typedef struct {
  float16 score;
  int16 index;
} LaneBest;

MA_FN void keepBetter(LaneBest* best, float16 score, int16 index, int gridSize) {
  int16 better = score > best->score && index < gridSize;
  best->score = select(best->score, score, better);
  best->index = select(best->index, index, better);
}

MA_FN int bestIndex(LaneBest best) {
  float score[16];
  int index[16];
  vstore16(best.score, 0, score);
  vstore16(best.index, 0, index);
  int l = -1;
  float top = -INFINITY;
  for (int lane = 0; lane < 16; ++lane) {
    if (score[lane] > top || (score[lane] == top && index[lane] < l)) {
      top = score[lane];
      l = index[lane];
    }
  }
  return l;
}

// The score of bestIndex's candidate: the highest, which no NaN reaches (keepBetter).
MA_FN float bestScore(LaneBest best) {
  float score[16];
  vstore16(best.score, 0, score);
  float top = -INFINITY;
  for (int lane = 0; lane < 16; ++lane) top = score[lane] > top ? score[lane] : top;
  return top;
}

// The running sums of the combinations l0 … l0 + MA_PASS − 1 of technique j, at
// `sums` = the pixel's first, brought to the current scale (sumsRescale; 0: none yet).
MA_FN void loadSums(__global const float* sums, int j, int l0, int paddedSize, float rescale, float16* sumG,
                    float16* sumG2) {
  __global const float* s = sums + runningSumIndex(j, 0, l0, paddedSize);
  __global const float* s2 = sums + runningSumIndex(j, 1, l0, paddedSize);
  for (int v = 0; v < MA_GRID_VECTORS; ++v) sumG[v] = sumG2[v] = 0.0f;
  if (rescale == 0.0f) return;
  float rescale2 = rescale * rescale;
  for (int v = 0; v < MA_GRID_VECTORS; ++v) {
    sumG[v] = vload16(v, s) * rescale;
    sumG2[v] = vload16(v, s2) * rescale2;
  }
}

// The sums back where loadSums found them, for the next search.
MA_FN void storeSums(__global float* sums, int j, int l0, int paddedSize, const float16* sumG, const float16* sumG2) {
  for (int v = 0; v < MA_GRID_VECTORS; ++v) {
    vstore16(sumG[v], v, sums + runningSumIndex(j, 0, l0, paddedSize));
    vstore16(sumG2[v], v, sums + runningSumIndex(j, 1, l0, paddedSize));
  }
}

// P's pair of the combinations l0 … l0 + MA_PASS − 1, as loadSums reads a technique's
// sums; P has no scale: it is read as it is, or as 0 where there are no sums yet.
MA_FN void loadPair(__global const float* sums, int pair, int l0, int paddedSize, float rescale, float16* sumP) {
  for (int v = 0; v < MA_GRID_VECTORS; ++v)
    sumP[v] = rescale == 0.0f ? (float16)0.0f : vload16(v, sums + pairSumIndex(pair, l0, MA_TECHNIQUES, paddedSize));
}

MA_FN void storePair(__global float* sums, int pair, int l0, int paddedSize, const float16* sumP) {
  for (int v = 0; v < MA_GRID_VECTORS; ++v)
    vstore16(sumP[v], v, sums + pairSumIndex(pair, l0, MA_TECHNIQUES, paddedSize));
}

// [HS14] Alg. 1 lines 5–13 for one pixel: adds the samples prepared at `prepared`
// (summarised in `added`) to its running sums at `sums`, which it stores back if
// `keepSums` (a search follows that adds to them), and, if `rank`, returns the
// best l₀ by the sums of all its samples (summarised in `all`), or −1 if no
// combination could be ranked. Both rules score 16 combinations per float16.
MA_FN int searchPixel(__global const float* prepared, PixelSummary added, PixelSummary all, float rescale,
                      __global float* sums, int keepSums, int rank, __global const float* gridLanes,
                      __global const float* gridCost, int gridSize, int paddedSize, const float* cost, int rule,
                      __global float* scores) {
  float invCount[MA_TECHNIQUES], stageMix[MA_TECHNIQUES];
  for (int j = 0; j < MA_TECHNIQUES; ++j) invCount[j] = 1.0f / all.count[j];
  const float invTotal = 1.0f / sampleCount(MA_TECHNIQUES, all);
  stageMixture(MA_TECHNIQUES, added, stageMix);
  const int16 lanes = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  LaneBest best = {(float16)(-INFINITY), (int16)(-1)};
  for (int l0 = 0; l0 < gridSize; l0 += MA_PASS) {
    float16 alpha[MA_GRID_VECTORS][MA_TECHNIQUES];
    for (int v = 0; v < MA_GRID_VECTORS; ++v)
      for (int k = 0; k < MA_TECHNIQUES; ++k) alpha[v][k] = vload16(0, gridLanes + k * paddedSize + l0 + 16 * v);
    float16 sumG[MA_TECHNIQUES][MA_GRID_VECTORS], sumG2[MA_TECHNIQUES][MA_GRID_VECTORS];
    float16 sumP[MA_PAIR_COUNT][MA_GRID_VECTORS];
    for (int j = 0; j < MA_TECHNIQUES; ++j) loadSums(sums, j, l0, paddedSize, rescale, sumG[j], sumG2[j]);
#if MA_GRID_OPTIMAL_WEIGHTS
    for (int pair = 0; pair < MA_PAIR_COUNT; ++pair) loadPair(sums, pair, l0, paddedSize, rescale, sumP[pair]);
#endif
    if (rule == MA_RULE_MAX_ENTROPY) {
      for (int j = 0; j < MA_TECHNIQUES; ++j)
        sumTechnique(prepared + preparedFirst(added, j, MA_EVERY_SAMPLE) * (MA_TECHNIQUES + 1),
                     preparedCount(added, j, MA_EVERY_SAMPLE), alpha, sumG[j], sumG2[j]);
    } else {
      sumMixture(prepared, preparedFirst(added, MA_TECHNIQUES, MA_EVERY_SAMPLE), alpha, stageMix, sumG, sumG2[0], sumP);
    }
    if (keepSums) {
      for (int j = 0; j < MA_TECHNIQUES; ++j) storeSums(sums, j, l0, paddedSize, sumG[j], sumG2[j]);
#if MA_GRID_OPTIMAL_WEIGHTS
      for (int pair = 0; pair < MA_PAIR_COUNT; ++pair) storePair(sums, pair, l0, paddedSize, sumP[pair]);
#endif
    }
    if (!rank) continue;
    for (int v = 0; v < MA_GRID_VECTORS; ++v) {
      float16 g1[MA_TECHNIQUES], g2[MA_TECHNIQUES];
      for (int j = 0; j < MA_TECHNIQUES; ++j) {
        g1[j] = sumG[j][v];
        g2[j] = sumG2[j][v];
      }
      int16 index = l0 + 16 * v + lanes;
      float16 score;
      if (rule == MA_RULE_MAX_ENTROPY) {
        score = entropyScore16(MA_TECHNIQUES, alpha[v], vload16(0, gridCost + l0 + 16 * v), cost, g1, g2, invCount);
      } else {
#if MA_GRID_OPTIMAL_WEIGHTS
        float16 p[MA_PAIR_COUNT];
        for (int pair = 0; pair < MA_PAIR_COUNT; ++pair) p[pair] = sumP[pair][v];
        score = optimalVarianceScore16(MA_TECHNIQUES, vload16(0, gridCost + l0 + 16 * v), g1, g2[0], p, invTotal);
#else
        score = costVarianceScore16(MA_TECHNIQUES, alpha[v], vload16(0, gridCost + l0 + 16 * v), g1, g2[0], invTotal);
#endif
      }
      vstore16(score, 0, scores + l0 + 16 * v);
      keepBetter(&best, score, index, gridSize);
    }
  }
  return bestIndex(best);
}

// One work-item per block of 16 pixels. `taken` samples per pixel are new since the
// previous search; `summaries` (per pixel) and `sums` (sumRows rows per pixel) hold what the
// searches before added; `keepSums` 0 leaves `sums` unwritten (no search follows), and
// then the searches before must have added nothing. gridLanes[k · paddedSize + l] = α_{k,l} and gridCost[l] =
// Σ_k c_k α_{k,l}, both padded past gridSize with the last combination; cost[k] = c_k;
// `prepared` has taken · (M + 1) floats per pixel (prepareSample). Outputs per pixel: α
// (M floats), the selected index l₀ (−1 where the pixel fell back to equal weights),
// AllocationFallback bits, the score of every combination (paddedSize floats; written
// where the pixel did not fall back) and the scale of its sums (sampleScale), so that
// the host can pool the scores of neighbouring pixels (host/alloc/GridSearch.h, PooledSelection).
__kernel void gridSearch(__global const float* samples, int capacity, int taken, int pixelCount,
                         __global const float* gridLanes, __global const float* gridCost, int gridSize, int paddedSize,
                         __global const float* cost, int rule, __global float* prepared,
                         __global PixelSummary* summaries, __global float* sums, int keepSums, __global float* alphaOut,
                         __global int* selectedOut, __global uint* fallbacksOut, __global float* scoresOut,
                         __global float* scaleOut) {
  int block = (int)get_global_id(0);
  if (16 * block >= pixelCount) return;
  const int lanesUsed = min(16, pixelCount - 16 * block);
  __global const float* blockSamples = samples + (size_t)block * capacity * (MA_TECHNIQUES + 2) * 16;
  __global float* blockPrepared = prepared + (size_t)block * 16 * taken * (MA_TECHNIQUES + 1);
  // Lane-innermost passes over the samples read each row of 16 pixels once.
  PixelSummary added[16];
  for (int lane = 0; lane < 16; ++lane) added[lane] = emptySummary();
  for (int i = 0; i < taken; ++i)
    for (int lane = 0; lane < 16; ++lane)
      summariseSample(&added[lane], blockSamples + lane, MA_TECHNIQUES, MA_SHARE_COLUMNS, i);
  PixelSummary all[16];
  uint fallbacks[16];
  int next[16][MA_TECHNIQUES];
  float scale[16], rescale[16];
  for (int lane = 0; lane < lanesUsed; ++lane) {
    PixelSummary before = summaries[16 * block + lane];
    all[lane] = mergeSummaries(before, added[lane]);
    fallbacks[lane] = pixelFallbacks(MA_TECHNIQUES, all[lane], rule);
    scale[lane] = sampleScale(all[lane]);
    rescale[lane] = sumsRescale(before, scale[lane], MA_EVERY_SAMPLE);
    for (int j = 0; j < MA_TECHNIQUES; ++j) next[lane][j] = preparedFirst(added[lane], j, MA_EVERY_SAMPLE);
  }
  for (int i = 0; i < taken; ++i)
    for (int lane = 0; lane < lanesUsed; ++lane)
      if (hasSums(all[lane], MA_EVERY_SAMPLE))
        prepareSample(blockSamples + lane, MA_TECHNIQUES, i, scale[lane], MA_EVERY_SAMPLE, next[lane],
                      blockPrepared + lane * taken * (MA_TECHNIQUES + 1));

  float c[MA_TECHNIQUES];
  for (int k = 0; k < MA_TECHNIQUES; ++k) c[k] = cost[k];
  for (int lane = 0; lane < lanesUsed; ++lane) {
    int pixel = 16 * block + lane, best = -1;
    // Pixels that cannot be ranked yet keep their sums for the searches to come.
    if (hasSums(all[lane], MA_EVERY_SAMPLE))
      best = searchPixel(blockPrepared + lane * taken * (MA_TECHNIQUES + 1), added[lane], all[lane], rescale[lane],
                         sums + pixelSumsFirst(pixel, sumRows(MA_TECHNIQUES, MA_EVERY_SAMPLE), paddedSize), keepSums,
                         fallbacks[lane] == 0u, gridLanes, gridCost, gridSize, paddedSize, c, rule,
                         scoresOut + (size_t)pixel * paddedSize);
    // No combination could be ranked: non-finite sums, or for rule (a) no λ that
    // is a distribution (eq. 4.16 has no solution on the grid).
    if (fallbacks[lane] == 0u && best < 0)
      fallbacks[lane] = rule == MA_RULE_MAX_ENTROPY ? MA_FALLBACK_SINGULAR_SYSTEM : MA_FALLBACK_NON_FINITE;
    for (int k = 0; k < MA_TECHNIQUES; ++k)
      alphaOut[pixel * MA_TECHNIQUES + k] =
          fallbacks[lane] == 0u ? gridLanes[k * paddedSize + best] : 1.0f / MA_TECHNIQUES;
    selectedOut[pixel] = fallbacks[lane] == 0u ? best : -1;
    fallbacksOut[pixel] = fallbacks[lane];
    scaleOut[pixel] = scale[lane];
    summaries[pixel] = all[lane];
  }
}

// [HS14] Alg. 1 line 13, rule (b), over every pixel's window of `radius` (kernels/gridsearch.h,
// poolWindow), and the skip rule; one work-item per pixel. Reads gridSearch's outputs:
// the scores, scales, and its α, l₀ and fallbacks (alpha, selected, fallbacks), which a
// pixel with no ranked pixel in its window keeps. Writes α, l₀ (−1 where the pixel fell
// back or skipped), the fallback and skip flags, V(equal)/V(selected) as the window
// predicts it (pooledVarianceRatio; 1 where the pixel skipped or kept its own α), and
// the pixel's held-out variances at equal weights and at the weights it will run
// (heldOutVariance; NaN where the window did not leave it out or it kept its own α,
// 0 where its own samples could not be searched).
__kernel void selectPooled(__global const float* scores, __global const float* scales, __global const float* alpha,
                           __global const int* selected, __global const uint* fallbacks, __global const int* surfaces,
                           int width, int height, int radius, __global const float* gridLanes,
                           __global const float* gridCost, int gridSize, int paddedSize, int equal, float minGain,
                           __global float* alphaOut, __global int* selectedOut, __global uint* fallbacksOut,
                           __global uchar* skippedOut, __global float* varianceRatioOut, __global float* heldOutOut) {
  int pixel = (int)get_global_id(0);
  if (pixel >= width * height) return;
  PoolWindow w = poolWindow(pixel, width, height, radius, surfaces[pixel]);
  float scaleMin = INFINITY;
  for (int y = w.y0; y <= w.y1; ++y)
    for (int x = w.x0; x <= w.x1; ++x)
      if (pools(w, y * width + x, fallbacks[y * width + x], surfaces[y * width + x]))
        scaleMin = fmin(scaleMin, scales[y * width + x]);
  int best = -1, skipped = 0;
  float ratio = 1.0f;
  if (scaleMin < INFINITY) {
    const int16 lanes = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    LaneBest top = {(float16)(-INFINITY), (int16)(-1)};
    float pooledEqual = 0.0f;
    // A pass of MA_PASS combinations per visit of a neighbour: its factor once, and
    // MA_GRID_VECTORS independent chains. Each lane is Σ_q score_q,l · (scaleMin/scale_q)²
    // over the window's pooled pixels q in row-major order, one fma chain, as the
    // reference's pooledScore (host/alloc/GridSearch.cpp).
    for (int l0 = 0; l0 < gridSize; l0 += MA_PASS) {
      float16 sum[MA_GRID_VECTORS];
      MA_UNROLL
      for (int v = 0; v < MA_GRID_VECTORS; ++v) sum[v] = 0.0f;
      for (int y = w.y0; y <= w.y1; ++y)
        for (int x = w.x0; x <= w.x1; ++x) {
          int q = y * width + x;
          if (!pools(w, q, fallbacks[q], surfaces[q])) continue;
          float16 factor = (float16)poolingFactor(scaleMin, scales[q]);
          __global const float* s = scores + (size_t)q * paddedSize + l0;
          MA_UNROLL
          for (int v = 0; v < MA_GRID_VECTORS; ++v) sum[v] = fma(vload16(v, s), factor, sum[v]);
        }
      float passSums[MA_PASS];
      MA_UNROLL
      for (int v = 0; v < MA_GRID_VECTORS; ++v) {
        keepBetter(&top, sum[v], l0 + 16 * v + lanes, gridSize);
        vstore16(sum[v], v, passSums);
      }
      if (equal >= l0 && equal < l0 + MA_PASS) pooledEqual = passSums[equal - l0];
    }
    best = bestIndex(top);
    float sumD = 0.0f, sumD2 = 0.0f, count = 0.0f;
    for (int y = w.y0; y <= w.y1; ++y)
      for (int x = w.x0; x <= w.x1; ++x) {
        int q = y * width + x;
        if (!pools(w, q, fallbacks[q], surfaces[q])) continue;
        __global const float* s = scores + (size_t)q * paddedSize;
        float d = (s[best] - s[equal]) * poolingFactor(scaleMin, scales[q]);
        sumD += d;
        sumD2 = fma(d, d, sumD2);
        count += 1.0f;
      }
    float pooledBest = bestScore(top);
    skipped = skipsAdapting(pooledBest, pooledEqual, minGain, sumD, sumD2, count);
    if (!skipped && w.self >= 0) ratio = pooledVarianceRatio(pooledBest, gridCost[best], pooledEqual, gridCost[equal]);
  }
  for (int k = 0; k < MA_TECHNIQUES; ++k)
    alphaOut[pixel * MA_TECHNIQUES + k] = best < 0
                                              ? alpha[pixel * MA_TECHNIQUES + k]
                                              : (skipped ? 1.0f / MA_TECHNIQUES : gridLanes[k * paddedSize + best]);
  selectedOut[pixel] = best < 0 ? selected[pixel] : (skipped ? -1 : best);
  fallbacksOut[pixel] = best < 0 ? fallbacks[pixel] : 0u;
  skippedOut[pixel] = (uchar)skipped;
  varianceRatioOut[pixel] = ratio;
  float heldOutEqual = NAN, heldOutRun = NAN;
  if (best >= 0 && w.self >= 0) {
    __global const float* own = scores + (size_t)pixel * paddedSize;
    const int run = skipped ? equal : best;
    const int searched = fallbacks[pixel] == 0u;
    heldOutEqual = searched ? heldOutVariance(own[equal], gridCost[equal], scales[pixel]) : 0.0f;
    heldOutRun = searched ? heldOutVariance(own[run], gridCost[run], scales[pixel]) : 0.0f;
  }
  heldOutOut[2 * pixel] = heldOutEqual;
  heldOutOut[2 * pixel + 1] = heldOutRun;
}
