// 000 Algorithm 1, lines 5–13, for every pixel at once: each work-item searches the U
// weight combinations for 16 pixels, one per float16 lane, over the samples that
// kernels/sample.cl stored in the blocked layout of kernels/stats.h (storedSampleIndex).
// Host side: host/alloc/GridSearch.h; C++ reference: gridSearchReference there.
//
// Compile-time options (gridSearchOptions in host/alloc/GridSearch.cpp): MA_TECHNIQUES
// (M) and MA_GRID_CHUNK, the weight combinations summed in one pass over the samples.
//
// Shape (../shared/notes/pocl-performance.md): explicit float16 arithmetic reaches
// 512-bit code on PoCL, and MA_GRID_CHUNK · 2M accumulators are as many independent
// fma chains. Sums are float: g is scaled so that g ≤ 1/min α (no overflow), and the
// few hundred samples of a pixel lose ~√n ulps, far below the sampling noise of the
// estimates they feed.
#include "gridsearch.h"

#define MA_RECORD (MA_TECHNIQUES + 2)  // floats per stored sample: technique, f, p_0 … p_{M−1}

// One stored sample of 16 pixels.
typedef struct {
  float16 technique, f, pdf[MA_TECHNIQUES];
} SampleLanes;

MA_FN SampleLanes loadSample(__global const float* block, int i) {
  SampleLanes s;
  s.technique = vload16(i * MA_RECORD, block);
  s.f = vload16(i * MA_RECORD + 1, block);
  MA_UNROLL
  for (int k = 0; k < MA_TECHNIQUES; ++k) s.pdf[k] = vload16(i * MA_RECORD + 2 + k, block);
  return s;
}

MA_FN float16 pdfSum(SampleLanes s) {
  float16 sum = s.pdf[0];
  MA_UNROLL
  for (int k = 1; k < MA_TECHNIQUES; ++k) sum += s.pdf[k];
  return sum;
}

// 1 where lane's sample was drawn by technique j, else 0: the technique's sums take
// t_j · g, which is exact.
MA_FN float16 techniqueMask(SampleLanes s, int j) { return select((float16)0.0f, (float16)1.0f, s.technique == (float)j); }

// What pixelFallbacks needs, per lane, and the scale of g: 1 / max_i f_i / Σ_k p_k(x_i).
// Since p_α ≥ (min_k α_k) Σ_k p_k, every scaled g is at most 1 / min_k α_k.
typedef struct {
  float count[MA_TECHNIQUES][16], maxF[MA_TECHNIQUES][16];
  float16 scale;
  int16 invalid;
} BlockSummary;

MA_FN BlockSummary summarise(__global const float* block, int taken) {
  float16 count[MA_TECHNIQUES], maxF[MA_TECHNIQUES], maxRatio = 0.0f;
  int16 invalid = 0;
  MA_UNROLL
  for (int j = 0; j < MA_TECHNIQUES; ++j) count[j] = maxF[j] = 0.0f;
  for (int i = 0; i < taken; ++i) {
    SampleLanes s = loadSample(block, i);
    float16 pSum = pdfSum(s), drawn = 0.0f;
    invalid |= !(s.f >= 0.0f && s.f <= FLT_MAX) | (s.f > 0.0f && pSum == 0.0f);
    MA_UNROLL
    for (int k = 0; k < MA_TECHNIQUES; ++k) invalid |= !(s.pdf[k] >= 0.0f && s.pdf[k] <= FLT_MAX);
    maxRatio = fmax(maxRatio, s.f / select(pSum, (float16)1.0f, pSum == 0.0f));
    MA_UNROLL
    for (int j = 0; j < MA_TECHNIQUES; ++j) {
      float16 t = techniqueMask(s, j);
      count[j] += t;
      maxF[j] = fmax(maxF[j], t * s.f);
      drawn += t;
    }
    invalid |= drawn == 0.0f;  // a technique index outside 0 … M−1
  }
  BlockSummary summary;
  MA_UNROLL
  for (int j = 0; j < MA_TECHNIQUES; ++j) {
    vstore16(count[j], 0, summary.count[j]);
    vstore16(maxF[j], 0, summary.maxF[j]);
  }
  summary.scale = select(1.0f / maxRatio, (float16)1.0f, maxRatio == 0.0f);
  summary.invalid = invalid;
  return summary;
}

// Σ g and Σ g² over each technique's samples, g = scale · f / p_α, for MA_GRID_CHUNK
// weight combinations (000 Alg. 1 line 8; eq. 6.6 and 6.8 before dividing by m_j).
typedef struct {
  float sumG[MA_GRID_CHUNK][MA_TECHNIQUES][16], sumG2[MA_GRID_CHUNK][MA_TECHNIQUES][16];
} ChunkSums;

MA_FN ChunkSums sumChunk(__global const float* block, int taken, float16 scale,
                         const float alpha[MA_GRID_CHUNK][MA_TECHNIQUES]) {
  float16 sumG[MA_GRID_CHUNK][MA_TECHNIQUES], sumG2[MA_GRID_CHUNK][MA_TECHNIQUES];
  MA_UNROLL
  for (int c = 0; c < MA_GRID_CHUNK; ++c) {
    MA_UNROLL
    for (int j = 0; j < MA_TECHNIQUES; ++j) sumG[c][j] = sumG2[c][j] = 0.0f;
  }
  for (int i = 0; i < taken; ++i) {
    SampleLanes s = loadSample(block, i);
    float16 fs = s.f * scale;
    // Where every p_k = 0, f = 0 as well (else the lane fell back): g must be 0 there,
    // not 0/0, and p_0 = 1 makes p_α = α_0 > 0.
    s.pdf[0] = select(s.pdf[0], (float16)1.0f, pdfSum(s) == 0.0f);
    float16 t[MA_TECHNIQUES];
    MA_UNROLL
    for (int j = 0; j < MA_TECHNIQUES; ++j) t[j] = techniqueMask(s, j);
    MA_UNROLL
    for (int c = 0; c < MA_GRID_CHUNK; ++c) {
      float16 p = alpha[c][0] * s.pdf[0];
      MA_UNROLL
      for (int k = 1; k < MA_TECHNIQUES; ++k) p = fma((float16)alpha[c][k], s.pdf[k], p);
#if MA_RECIP_MODE == 1
      float16 r = as_float16((uint16)0x7EF311C3u - as_uint16(p));
      r = fma(r, fma(-p, r, 1.0f), r);
      r = fma(r, fma(-p, r, 1.0f), r);
      r = fma(r, fma(-p, r, 1.0f), r);
      float16 g = fs * r;
#elif MA_RECIP_MODE == 2
      float16 g = native_divide(fs, p);
#else
      float16 g = fs / p;
#endif
      MA_UNROLL
      for (int j = 0; j < MA_TECHNIQUES; ++j) {
        float16 tg = t[j] * g;
        sumG[c][j] += tg;
        sumG2[c][j] = fma(tg, g, sumG2[c][j]);
      }
    }
  }
  ChunkSums sums;
  MA_UNROLL
  for (int c = 0; c < MA_GRID_CHUNK; ++c) {
    MA_UNROLL
    for (int j = 0; j < MA_TECHNIQUES; ++j) {
      vstore16(sumG[c][j], 0, sums.sumG[c][j]);
      vstore16(sumG2[c][j], 0, sums.sumG2[c][j]);
    }
  }
  return sums;
}

// One work-item per 16 pixels. Outputs per pixel: α (M floats), the selected index l₀
// (−1 where the pixel fell back to equal weights) and AllocationFallback bits.
// gridAlpha[l·M + k] = α_{k,l}, gridCost[l] = Σ_k c_k α_{k,l}, cost[k] = c_k.
__kernel void gridSearch(__global const float* samples, int capacity, int taken, int pixelCount,
                         __global const float* gridAlpha, __global const float* gridCost, int gridSize,
                         __global const float* cost, int rule, __global float* alphaOut, __global int* selectedOut,
                         __global uint* fallbacksOut) {
  int block = (int)get_global_id(0);
  if (16 * block >= pixelCount) return;
  __global const float* blockSamples = samples + (size_t)block * capacity * MA_RECORD * 16;
  BlockSummary summary = summarise(blockSamples, taken);
  int invalid[16];
  vstore16(summary.invalid, 0, invalid);

  float c[MA_TECHNIQUES], bestScore[16];
  MA_UNROLL
  for (int k = 0; k < MA_TECHNIQUES; ++k) c[k] = cost[k];
  int best[16], searchable = 0;
  uint fallbacks[16];
  for (int lane = 0; lane < 16; ++lane) {
    float count[MA_TECHNIQUES], maxF[MA_TECHNIQUES];
    for (int j = 0; j < MA_TECHNIQUES; ++j) {
      count[j] = summary.count[j][lane];
      maxF[j] = summary.maxF[j][lane];
    }
    fallbacks[lane] = pixelFallbacks(MA_TECHNIQUES, count, maxF, invalid[lane]);
    searchable |= fallbacks[lane] == 0u && 16 * block + lane < pixelCount;
    bestScore[lane] = -INFINITY;
    best[lane] = -1;
  }

  for (int l0 = 0; searchable && l0 < gridSize; l0 += MA_GRID_CHUNK) {
    // A last chunk past the grid repeats its final combination, which never wins a tie.
    float alpha[MA_GRID_CHUNK][MA_TECHNIQUES], meanCost[MA_GRID_CHUNK];
    for (int ci = 0; ci < MA_GRID_CHUNK; ++ci) {
      int l = min(l0 + ci, gridSize - 1);
      meanCost[ci] = gridCost[l];
      for (int k = 0; k < MA_TECHNIQUES; ++k) alpha[ci][k] = gridAlpha[l * MA_TECHNIQUES + k];
    }
    ChunkSums sums = sumChunk(blockSamples, taken, summary.scale, alpha);
    for (int lane = 0; lane < 16; ++lane) {
      if (fallbacks[lane] != 0u) continue;
      float count[MA_TECHNIQUES];
      for (int j = 0; j < MA_TECHNIQUES; ++j) count[j] = summary.count[j][lane];
      for (int ci = 0; ci < MA_GRID_CHUNK; ++ci) {
        float sumG[MA_TECHNIQUES], sumG2[MA_TECHNIQUES];
        for (int j = 0; j < MA_TECHNIQUES; ++j) {
          sumG[j] = sums.sumG[ci][j][lane];
          sumG2[j] = sums.sumG2[ci][j][lane];
        }
        float score = gridScore(rule, MA_TECHNIQUES, alpha[ci], meanCost[ci], c, sumG, sumG2, count);
        if (score > bestScore[lane]) {
          bestScore[lane] = score;
          best[lane] = min(l0 + ci, gridSize - 1);
        }
      }
    }
  }

  for (int lane = 0; lane < 16; ++lane) {
    int pixel = 16 * block + lane;
    if (pixel >= pixelCount) break;
    // No combination could be ranked: non-finite sums, or for rule (a) no λ that is a
    // distribution (eq. 4.16 has no solution on the grid).
    if (fallbacks[lane] == 0u && best[lane] < 0)
      fallbacks[lane] = rule == MA_RULE_MAX_ENTROPY ? MA_FALLBACK_SINGULAR_SYSTEM : MA_FALLBACK_NON_FINITE;
    for (int k = 0; k < MA_TECHNIQUES; ++k)
      alphaOut[pixel * MA_TECHNIQUES + k] =
          fallbacks[lane] == 0u ? gridAlpha[best[lane] * MA_TECHNIQUES + k] : 1.0f / MA_TECHNIQUES;
    selectedOut[pixel] = fallbacks[lane] == 0u ? best[lane] : -1;
    fallbacksOut[pixel] = fallbacks[lane];
  }
}
