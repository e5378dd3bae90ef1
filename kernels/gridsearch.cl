// 000 Algorithm 1, lines 5–13, for every pixel at once: one work-item per pixel
// searches the U weight combinations, 16 of them per float16, over the samples that
// kernels/sample.cl stored (kernels/stats.h, storedSampleIndex). Host side and C++
// reference: host/alloc/GridSearch.h. What both share: kernels/gridsearch.h.
//
// Compile-time options (GridSearch's constructor): MA_TECHNIQUES (M) and
// MA_GRID_VECTORS (B), the float16s of combinations summed in one pass over the samples.
//
// Shape (../shared/notes/pocl-performance.md): explicit float16 arithmetic is what
// reaches 512-bit code on PoCL. Lanes are combinations, not pixels, so a sample's
// technique is the same in every lane: its sums need no masks. A division has the same
// throughput per lane at 512 and 256 bits, so the B quotients f/p_α of one sample
// share one (MA_BATCH_QUOTIENTS), leaving multiplies, and 2B independent accumulator
// chains. Sums are float: the scaling keeps g ≤ 1/min α, and summing a few hundred
// samples in order loses ~√n ulps, far below the sampling noise of the estimates.
#include "gridsearch.h"

#define MA_PASS (16 * MA_GRID_VECTORS)  // combinations per pass over the samples

// Σ g and Σ g² of one technique's samples for the combinations l0 … l0 + MA_PASS − 1
// (000 Alg. 1 line 8; eq. 6.6 and 6.8 before dividing by m_j). alpha[c][k] holds α_k
// of the 16 combinations of vector c.
MA_FN void sumTechnique(__global const float* pixelSamples, int taken, int j, float scale,
                        const float16 alpha[MA_GRID_VECTORS][MA_TECHNIQUES], float* sumG, float* sumG2) {
  float16 s[MA_GRID_VECTORS], s2[MA_GRID_VECTORS];
  MA_UNROLL
  for (int c = 0; c < MA_GRID_VECTORS; ++c) s[c] = s2[c] = 0.0f;
  for (int i = 0; i < taken; ++i) {
    // kernels/sample.cl stores each stage's samples technique by technique, so this
    // branch is predictable.
    if ((int)storedValue(pixelSamples, MA_TECHNIQUES, i, 0) != j) continue;
    ScaledSample x = scaledSample(pixelSamples, MA_TECHNIQUES, i, scale);
    float16 p[MA_GRID_VECTORS], g[MA_GRID_VECTORS];
    MA_UNROLL
    for (int c = 0; c < MA_GRID_VECTORS; ++c) {
      p[c] = alpha[c][0] * x.q[0];
      MA_UNROLL
      for (int k = 1; k < MA_TECHNIQUES; ++k) p[c] = fma(alpha[c][k], (float16)x.q[k], p[c]);
    }
    MA_BATCH_QUOTIENTS(float16, MA_GRID_VECTORS, (float16)x.f, p, g);
    MA_UNROLL
    for (int c = 0; c < MA_GRID_VECTORS; ++c) {
      s[c] += g[c];
      s2[c] = fma(g[c], g[c], s2[c]);
    }
  }
  MA_UNROLL
  for (int c = 0; c < MA_GRID_VECTORS; ++c) {
    vstore16(s[c], c, sumG);
    vstore16(s2[c], c, sumG2);
  }
}

// One work-item per pixel. gridLanes[k · paddedSize + l] = α_{k,l} (padded past
// gridSize with the last combination), gridCost[l] = Σ_k c_k α_{k,l}, cost[k] = c_k.
// Outputs per pixel: α (M floats), the selected index l₀ (−1 where the pixel fell back
// to equal weights) and AllocationFallback bits.
__kernel void gridSearch(__global const float* samples, int capacity, int taken, int pixelCount,
                         __global const float* gridLanes, __global const float* gridCost, int gridSize,
                         int paddedSize, __global const float* cost, int rule, __global float* alphaOut,
                         __global int* selectedOut, __global uint* fallbacksOut) {
  int pixel = (int)get_global_id(0);
  if (pixel >= pixelCount) return;
  __global const float* pixelSamples = samples + (size_t)(pixel / 16) * capacity * (MA_TECHNIQUES + 2) * 16 + pixel % 16;
  PixelSummary summary = summarisePixel(pixelSamples, MA_TECHNIQUES, taken);
  uint fallbacks = pixelFallbacks(MA_TECHNIQUES, summary);
  float c[MA_TECHNIQUES], invCount[MA_TECHNIQUES];
  for (int k = 0; k < MA_TECHNIQUES; ++k) {
    c[k] = cost[k];
    invCount[k] = 1.0f / summary.count[k];
  }
  float bestScore = -INFINITY;
  int best = -1;
  for (int l0 = 0; fallbacks == 0u && l0 < gridSize; l0 += MA_PASS) {
    float16 alpha[MA_GRID_VECTORS][MA_TECHNIQUES];
    for (int v = 0; v < MA_GRID_VECTORS; ++v)
      for (int k = 0; k < MA_TECHNIQUES; ++k) alpha[v][k] = vload16(0, gridLanes + k * paddedSize + l0 + 16 * v);
    float sumG[MA_TECHNIQUES][MA_PASS], sumG2[MA_TECHNIQUES][MA_PASS];
    for (int j = 0; j < MA_TECHNIQUES; ++j)
      sumTechnique(pixelSamples, taken, j, summary.scale, alpha, sumG[j], sumG2[j]);
    for (int n = 0; n < MA_PASS && l0 + n < gridSize; ++n) {
      float a[MA_TECHNIQUES], g1[MA_TECHNIQUES], g2[MA_TECHNIQUES];
      for (int j = 0; j < MA_TECHNIQUES; ++j) {
        a[j] = gridLanes[j * paddedSize + l0 + n];
        g1[j] = sumG[j][n];
        g2[j] = sumG2[j][n];
      }
      float score = gridScore(rule, MA_TECHNIQUES, a, gridCost[l0 + n], c, g1, g2, invCount);
      if (score > bestScore) {
        bestScore = score;
        best = l0 + n;
      }
    }
  }
  // No combination could be ranked: non-finite sums, or for rule (a) no λ that is a
  // distribution (eq. 4.16 has no solution on the grid).
  if (fallbacks == 0u && best < 0)
    fallbacks = rule == MA_RULE_MAX_ENTROPY ? MA_FALLBACK_SINGULAR_SYSTEM : MA_FALLBACK_NON_FINITE;
  for (int k = 0; k < MA_TECHNIQUES; ++k)
    alphaOut[pixel * MA_TECHNIQUES + k] = fallbacks == 0u ? gridLanes[k * paddedSize + best] : 1.0f / MA_TECHNIQUES;
  selectedOut[pixel] = fallbacks == 0u ? best : -1;
  fallbacksOut[pixel] = fallbacks;
}
