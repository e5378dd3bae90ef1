// Resampled importance sampling ([TCE05]) of the envmap technique: a sample draws M
// candidates x_i from the envmap pdf p, exactly as envmap sampling draws, weighs each by
// w_i = p̂(x_i)/p(x_i) with the target p̂ = Y(f), the luminance of the integrand L ρ cos,
// keeps one, y, with probability w_y/Σ_i w_i, and estimates the integral by
// f(y)/p̂(y) · (1/M) Σ_i w_i, 0 where every w_i = 0. Unbiased where p > 0 wherever f ≠ 0
// (host/render/RunChecks.h refuses the envmap pdfs that are zero there). Host side:
// host/render/Method.h (`ris`), host/sampling/Sampler.cpp (MA_RIS_CANDIDATES = M).
#include "namespace_check.h"
#ifndef MA_RIS_H
#define MA_RIS_H
#include "estimator.h"

typedef struct {
  SampleValue value;         // f and every p_k at y
  float contributionWeight;  // (1/M) Σ_i w_i / p̂(y): the estimate is f(y) times it; 0 if none was kept
} ResampledSample;

MA_FN SampleValue selectSampleValue(int first, SampleValue a, SampleValue b) {
  SampleValue s;
  s.r = first ? a.r : b.r;
  s.g = first ? a.g : b.g;
  s.b = first ? a.b : b.b;
  MA_UNROLL
  for (int k = 0; k < MA_MAX_TECHNIQUES; ++k) s.pdfs[k] = first ? a.pdfs[k] : b.pdfs[k];
  MA_UNROLL
  for (int k = 0; k < MA_MAX_BANK_SHARES; ++k) s.sharePdfs[k] = first ? a.sharePdfs[k] : b.sharePdfs[k];
  return s;
}

// Sample `index` of the envmap technique, resampled from `candidates` candidates in one
// pass: a weighted reservoir keeps candidate i with probability w_i / Σ_{l≤i} w_l, so y
// is x_i with probability w_i / Σ_l w_l. Candidate i takes part i of the envmap stream's
// draw `index` (candidate 0 is envmap sampling's own sample `index`); its coin is word
// i mod 4 of part i/4 of the resampling stream's. The kernel unrolls the loop (M is
// compiled in; docs/pocl.md, rule 1), which folds its one branch, the coins' draw.
MA_FN ResampledSample resampleEnvmap(TechniqueSet ts, EnvmapView env, ShadingPoint sp, int candidates, ma_uint seedLo,
                                     ma_uint seedHi, ma_uint pixel, ma_uint index) {
  SampleValue kept;
  kept.r = kept.g = kept.b = 0.0f;
  MA_UNROLL
  for (int k = 0; k < MA_MAX_TECHNIQUES; ++k) kept.pdfs[k] = 0.0f;
  float weightSum = 0.0f;
  MaRandom4 coins = {{0u, 0u, 0u, 0u}};  // drawn at i = 0
  MA_UNROLL
  for (int i = 0; i < candidates; ++i) {
    if (i % 4 == 0) coins = philoxDrawPart(seedLo, seedHi, pixel, MA_STREAM_RESAMPLING_CHOICE, index, (ma_uint)(i / 4));
    MaRandom4 rnd = philoxDrawPart(seedLo, seedHi, pixel, (ma_uint)MA_TECHNIQUE_ENVMAP, index, (ma_uint)i);
    SampleValue x =
        evaluateSample(ts, env, sp, MA_TECHNIQUE_ENVMAP, sampleTechnique(ts, env, sp, MA_TECHNIQUE_ENVMAP, rnd, 0.0f));
    // [TCE05]: w = p̂/p. A candidate's texel was drawn, so p > 0 but for underflow.
    float w = x.pdfs[0] > 0.0f ? luminance(x.r, x.g, x.b) / x.pdfs[0] : 0.0f;
    weightSum += w;
    // u < w / Σ, without the division: never where w = 0.
    kept = selectSampleValue(uniformFloat(coins.v[i % 4]) * weightSum < w, x, kept);
  }
  float target = luminance(kept.r, kept.g, kept.b);
  ResampledSample y;
  y.value = kept;
  // [TCE05]: f(y)/p̂(y) · (1/M) Σ_i w_i. A kept y has w_y > 0, so p̂(y) > 0.
  y.contributionWeight = target > 0.0f ? weightSum / ((float)candidates * target) : 0.0f;
  return y;
}

#endif
