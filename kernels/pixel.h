// One pixel's share of a sampling stage: which technique takes sample j, the sample's
// contribution to the estimate, and the running sums the allocations use. Shared by
// kernels/sample.cl and its C++ reference (host/sampling/HostSampler.cpp). Everything is
// scalar fields, not arrays: PoCL keeps a kernel scalar that indexes private arrays
// dynamically.
#include "namespace_check.h"
#ifndef MA_PIXEL_H
#define MA_PIXEL_H
#include "estimator.h"
#include "pixel_layout.h"
#include "pixel_optimal.h"
#include "ris.h"

typedef struct {
  int techniqueCount, stageSamples, oneSample;
  int countIndependent;            // [SHS16] eq. 26 instead of the balance heuristic
  int risCandidates;               // > 0: technique 0 resamples this many envmap candidates ([TCE05])
  int n0, n1, n2;                  // this stage's counts (one-sample: expected counts)
  ma_uint first0, first1, first2;  // index of each technique's first sample this stage
} StageCounts;

// A pixel's StageCounts from the stage's per-pixel arrays ([pixel·M + k]), as the
// kernel and its C++ reference both read them.
MA_FN StageCounts loadStageCounts(MA_GLOBAL const int* counts, MA_GLOBAL const ma_uint* firstIndex, int pixel,
                                  int techniqueCount, int stageSamples, int oneSample, int countIndependent,
                                  int risCandidates) {
  MA_GLOBAL const int* n = counts + countsOffset(pixel, techniqueCount);
  MA_GLOBAL const ma_uint* first = firstIndex + countsOffset(pixel, techniqueCount);
  StageCounts c;
  c.techniqueCount = techniqueCount;
  c.stageSamples = stageSamples;
  c.oneSample = oneSample;
  c.countIndependent = countIndependent;
  c.risCandidates = risCandidates;
  c.n0 = n[0];
  c.n1 = n[1];
  c.n2 = techniqueCount > 2 ? n[techniqueCount - 1] : 0;
  c.first0 = first[0];
  c.first1 = first[1];
  c.first2 = techniqueCount > 2 ? first[techniqueCount - 1] : 0u;
  return c;
}

// How many samples the pixel takes this stage: N, or 0 for the background, which takes
// none (host/render/Method.h, leaveOutBackground).
MA_FN int pixelStageSamples(StageCounts c) { return c.n0 + c.n1 + c.n2; }

// The index of `technique`'s first sample this stage (its random-number stream).
MA_FN ma_uint firstIndexOf(StageCounts c, int technique) {
  return technique == 0 ? c.first0 : (technique == 1 ? c.first1 : c.first2);
}

typedef struct {
  int technique;
  int share;      // the share column the stage's envmap samples draw with (stageShareColumn)
  float r, g, b;  // the sample's term of the stage estimate
  float w;        // its luminance value: Y(f)/p_α (balance), Y(f)/Σ_k p_k (count-independent),
                  // (1/M) Σ_i w_i (resampled)
  float y;        // Y(f)
  float pdfs[MA_MAX_TECHNIQUES];
  float sharePdfs[MA_MAX_BANK_SHARES];  // SampleValue::sharePdfs
  float fr, fg, fb;                     // f itself, for the optimal weights and their sums (stats.h)
  float invP;                           // 1/p_α (balance), 1/Σ_k p_k (count-independent); 0 where it is 0
} SampleContribution;

typedef struct {
  ma_acc r, g, b;        // Σ f / (N p_α): this stage's unbiased estimate
  ma_acc w0, w1, w2;     // per technique: Σ w
  ma_acc ww0, ww1, ww2;  // per technique: Σ w²
} PixelSums;

// α_k = n_k / N: each technique's share of the stage (one-sample: its probability).
MA_FN void stageFractions(StageCounts c, float* alpha) {
  float N = (float)c.stageSamples;
  alpha[0] = (float)c.n0 / N;
  alpha[1] = (float)c.n1 / N;
  alpha[2] = (float)c.n2 / N;
}

// The envmap share C by which a stage picks the optimal pdf's bank entry ([Kar19] eq. 9,
// q = (1−C) p_ρ): α_0, or with the product technique n_0 against n_0 + n_1. The product's
// samples, ∝ f, shrink the f that the other two share and leave their ratio to C. From
// the counts, one division: α_0 and α_1 divided together would be packed into a short
// vector, which stops PoCL vectorising the sample loop (docs/pocl.md, rule 8).
MA_FN float bankEnvmapFraction(int product, int n0, int n1, float alpha0) {
  return product ? (float)n0 / (float)(n0 + n1 > 0 ? n0 + n1 : 1) : alpha0;
}

// The stage's envmap share C as bankEnvmapFraction takes it: the share that the bank's
// entry and the optimal pdf per pixel are chosen or built for.
MA_FN float stageEnvmapShare(int product, StageCounts c) {
  return bankEnvmapFraction(product, c.n0, c.n1, (float)c.n0 / (float)c.stageSamples);
}

// Whether the stage draws BRDF samples (technique 1), which cover every direction where
// f ≠ 0: the optimal pdf per pixel then needs no plain share (kernels/pixel_optimal.h).
MA_FN int stageDrawsBrdf(StageCounts c) { return c.n1 > 0; }

// The share column whose table the stage's envmap samples draw with: the bank's entry's,
// or for the optimal pdf per pixel the share nearest the stage's own C, which its table
// is built for; 0 where there are no shares.
MA_FN int stageShareColumn(EnvmapView env, int sharePdfs, float envmapFraction) {
  int shares = env.bankShares > 0 ? env.bankShares : (sharePdfs && env.pixelCells > 0 ? MA_MAX_BANK_SHARES : 0);
  return shares > 0 ? bankShareOf(shares, envmapFraction) : 0;
}

// The sample of `technique` with that technique's sample index `index`.
MA_FN SampleContribution takeTechniqueSample(TechniqueSet ts, EnvmapView env, ShadingPoint sp, StageCounts c,
                                             int technique, ma_uint index, ma_uint seedLo, ma_uint seedHi,
                                             ma_uint pixel) {
  float N = (float)c.stageSamples;
  float alpha[MA_MAX_TECHNIQUES];
  stageFractions(c, alpha);
  float bankFraction = bankEnvmapFraction(productEnabled(ts.product), c.n0, c.n1, alpha[0]);
  if (env.bankShares > 0) env.bankEntry = bankEntryOf(env, bankFraction);
  SampleValue s;
  float invP, scale;
  if (technique == MA_TECHNIQUE_ENVMAP && c.risCandidates > 0) {
    // [TCE05]: f(y) times the resampled sample's weight, over N.
    ResampledSample y = resampleEnvmap(ts, env, sp, c.risCandidates, seedLo, seedHi, pixel, index);
    s = y.value;
    invP = y.contributionWeight;
    scale = N;
  } else {
    MaRandom4 rnd = philoxDraw(seedLo, seedHi, pixel, (ma_uint)technique, index);
    // The product technique's choice of table takes a word of the draw's next part.
    float mixtureU = isProductTechnique(ts, technique)
                         ? uniformFloat(philoxDrawPart(seedLo, seedHi, pixel, (ma_uint)technique, index, 1u).v[0])
                         : 0.0f;
    s = evaluateSample(ts, env, sp, technique, sampleTechnique(ts, env, sp, technique, rnd, mixtureU));
    // Balance heuristic: f / (N p_α), p_α = Σ_k α_k p_k ([HS14] eq. 4.2). Count-independent
    // weights p_t/Σ_k p_k: f / (n_t Σ_k p_k) ([SHS16] eq. 26).
    float nt = technique == 0 ? (float)c.n0 : (technique == 1 ? (float)c.n1 : (float)c.n2);
    float mix[MA_MAX_TECHNIQUES];
    MA_UNROLL
    for (int k = 0; k < MA_MAX_TECHNIQUES; ++k) mix[k] = c.countIndependent ? 1.0f : alpha[k];
    float p = mixturePdf(c.techniqueCount, mix, s.pdfs);
    scale = c.countIndependent ? nt : N;
    // p = 0 only where no technique can sample, so f = 0 there too.
    invP = p > 0.0f ? 1.0f / p : 0.0f;
  }
  SampleContribution out;
  out.technique = technique;
  out.share = stageShareColumn(env, ts.sharePdfs, bankFraction);
  out.r = s.r * invP / scale;
  out.g = s.g * invP / scale;
  out.b = s.b * invP / scale;
  out.y = luminance(s.r, s.g, s.b);
  out.w = out.y * invP;
  MA_UNROLL
  for (int k = 0; k < MA_MAX_TECHNIQUES; ++k) out.pdfs[k] = s.pdfs[k];
  // The optimal pdf per pixel's stage table is built for its own C, not the column's:
  // the column it draws with holds the pdf it was weighted with, so that the search's
  // mixture of the drawn pdfs is the one that drew them.
  int ownTable = env.pixelCells > 0 && ts.sharePdfs;
  MA_UNROLL
  for (int k = 0; k < MA_MAX_BANK_SHARES; ++k)
    out.sharePdfs[k] = ownTable && k == out.share ? s.pdfs[0] : s.sharePdfs[k];
  out.fr = s.r;
  out.fg = s.g;
  out.fb = s.b;
  out.invP = invP;
  return out;
}

// The coefficients a_{c,k} of [Kon19]'s optimal weights, per colour channel c and
// technique k, solved per pixel from earlier stages (host/alloc/OptimalWeights.h); all 0
// is the balance heuristic.
typedef struct {
  float a[3][MA_MAX_TECHNIQUES];
} OptimalCoefficients;

// [Kon19] Sec. 4 (docs/papers.md): with the optimal weights
// w_t = a_t p_t/f + (n_t p_t / Σ_l n_l p_l)(1 − Σ_l a_l p_l/f), a sample of technique t
// adds w_t f/(n_t p_t) = a_t/n_t + (f − Σ_l a_l p_l)/(N p_α): over the stage, Σ_k a_k plus
// the balance heuristic of the residual f − Σ_l a_l p_l. Unbiased for any a, provided
// every p_k integrates to 1 and every technique takes a sample (render/RunChecks.h). The
// luminance value w becomes the residual's, Y(f − Σ_l a_l p_l)/p_α, whose per-technique
// moments give the stage's variance as before (alloc/StageWeights.h). With a = 0 every
// value is the balance heuristic's, bit for bit.
MA_FN SampleContribution withOptimalWeights(SampleContribution s, StageCounts c, OptimalCoefficients k) {
  float N = (float)c.stageSamples;
  float nt = s.technique == 0 ? (float)c.n0 : (s.technique == 1 ? (float)c.n1 : (float)c.n2);
  float f[3] = {s.fr, s.fg, s.fb}, residual[3], term[3];
  MA_UNROLL
  for (int ch = 0; ch < 3; ++ch) {
    float ap = 0.0f;
    MA_UNROLL
    for (int l = 0; l < c.techniqueCount; ++l) ap = ma_fma(k.a[ch][l], s.pdfs[l], ap);
    float at = s.technique == 0 ? k.a[ch][0] : (s.technique == 1 ? k.a[ch][1] : k.a[ch][2]);
    residual[ch] = f[ch] - ap;
    term[ch] = residual[ch] * s.invP / N + at / nt;
  }
  s.r = term[0];
  s.g = term[1];
  s.b = term[2];
  s.w = luminance(residual[0], residual[1], residual[2]) * s.invP;
  return s;
}

// Sample j of the stage. Multi-sample: the first n0 samples are technique 0's, the next
// n1 technique 1's, ... One-sample: the technique is drawn with probabilities α_k.
MA_FN SampleContribution takeStageSample(TechniqueSet ts, EnvmapView env, ShadingPoint sp, StageCounts c, int j,
                                         ma_uint seedLo, ma_uint seedHi, ma_uint pixel) {
  int technique;
  ma_uint index;
  if (c.oneSample) {
    float alpha[MA_MAX_TECHNIQUES];
    stageFractions(c, alpha);
    MaRandom4 choice = philoxDraw(seedLo, seedHi, pixel, MA_STREAM_TECHNIQUE_CHOICE, c.first0 + (ma_uint)j);
    technique = chooseTechnique(c.techniqueCount, alpha, uniformFloat(choice.v[0]));
    index = c.first0 + (ma_uint)j;
  } else {
    technique = j < c.n0 ? 0 : (j < c.n0 + c.n1 ? 1 : 2);
    int start = technique == 0 ? 0 : (technique == 1 ? c.n0 : c.n0 + c.n1);
    index = firstIndexOf(c, technique) + (ma_uint)(j - start);
  }
  return takeTechniqueSample(ts, env, sp, c, technique, index, seedLo, seedHi, pixel);
}

MA_FN PixelSums zeroPixelSums(void) {
  PixelSums z;
  z.r = z.g = z.b = 0;
  z.w0 = z.w1 = z.w2 = 0;
  z.ww0 = z.ww1 = z.ww2 = 0;
  return z;
}

MA_FN void addContribution(PixelSums* sums, SampleContribution s) {
  sums->r += (ma_acc)s.r;
  sums->g += (ma_acc)s.g;
  sums->b += (ma_acc)s.b;
  ma_acc w = (ma_acc)s.w, ww = w * w;
  sums->w0 += s.technique == 0 ? w : 0;
  sums->w1 += s.technique == 1 ? w : 0;
  sums->w2 += s.technique == 2 ? w : 0;
  sums->ww0 += s.technique == 0 ? ww : 0;
  sums->ww1 += s.technique == 1 ? ww : 0;
  sums->ww2 += s.technique == 2 ? ww : 0;
}

#endif
