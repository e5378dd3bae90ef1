// The running per-pixel sums that the allocations estimate their statistics from
// (host/stats/PixelStats.h, which decodes them). A stage adds each sample to the sums
// of the technique that drew it; MA_STATS chooses which sums a method keeps, so that
// each method stores only what it reads.
#include "namespace_check.h"
#ifndef MA_STATS_H
#define MA_STATS_H
#include "pixel.h"

#define MA_STATS_TECHNIQUE 1  // Σ f/p_k and Σ (f/p_k)²: V_k of [HS14] eq. 4.18 (heuristic)
#define MA_STATS_BALANCE 2    // Σ f/Σ_l p_l and its square: σ_k of [SHS16] eq. 27–28 (σ/√c)
#define MA_STATS_LINEAR 4     // F_k = Σ f and P_ik = Σ p_i: [SS23] eq. 18 (linear)
#define MA_STATS_OPTIMAL 8    // Σ r_i r_k, Σ (f_c/p_α) r_i, r = p/p_α: [Kon19]'s A and b (optimal weights)

// The optimal weights' sums per technique: the upper triangle of A, then b per channel.
#define MA_OPTIMAL_SYSTEM_SUMS(techniqueCount) ((techniqueCount) * ((techniqueCount) + 1) / 2 + 3 * (techniqueCount))

// Per technique: the count, then the sums that `mask` selects, in the order above; no
// slot at all when the method keeps no sums. A macro: kernels size local arrays with it.
#define MA_STATS_PER_TECHNIQUE(mask, techniqueCount)                                               \
  ((mask) == 0 ? 0                                                                                 \
               : 1 + (((mask)&MA_STATS_TECHNIQUE) ? 2 : 0) + (((mask)&MA_STATS_BALANCE) ? 2 : 0) + \
                     (((mask)&MA_STATS_LINEAR) ? 1 + (techniqueCount) : 0) +                       \
                     (((mask)&MA_STATS_OPTIMAL) ? MA_OPTIMAL_SYSTEM_SUMS(techniqueCount) : 0))

// What sample s adds to slot `slot` of the sums of the technique that drew it. Squares
// are taken in ma_acc: f/p can be near the top of the float range.
//
// The optimal weights' sums are count-free: a stage's samples x, drawn as the balance
// heuristic's mixture p_α of its counts ([HS14] eq. 4.3), give Σ_x h(x)/p_α(x) ≈ N ∫ h, so
// Σ_x p_i p_k/p_α² ≈ N ∫ p_i p_k/p_α = N Ã_ik and Σ_x f_c p_i/p_α² ≈ N b̃_ci: [Kon19]'s
// A = Ã/N and b = b̃/N at that stage's counts (host/alloc/OptimalWeights.h).
MA_FN ma_acc statValue(int mask, int techniqueCount, int slot, SampleContribution s) {
  float pt = s.technique == 0 ? s.pdfs[0] : (s.technique == 1 ? s.pdfs[1] : s.pdfs[2]);
  ma_acc w = pt > 0.0f ? (ma_acc)s.y / (ma_acc)pt : 0;
  float pSum = s.pdfs[0] + s.pdfs[1] + s.pdfs[2];
  ma_acc balance = pSum > 0.0f ? (ma_acc)s.y / (ma_acc)pSum : 0;
  int i = slot - 1;
  ma_acc value = slot == 0 ? (ma_acc)1 : (ma_acc)0;
  if (mask & MA_STATS_TECHNIQUE) {
    value = i == 0 ? w : (i == 1 ? w * w : value);
    i -= 2;
  }
  if (mask & MA_STATS_BALANCE) {
    value = i == 0 ? balance : (i == 1 ? balance * balance : value);
    i -= 2;
  }
  if (mask & MA_STATS_LINEAR) {
    value = i == 0 ? (ma_acc)s.y : value;
    value = i == 1 ? (ma_acc)s.pdfs[0] : (i == 2 ? (ma_acc)s.pdfs[1] : (i == 3 ? (ma_acc)s.pdfs[2] : value));
    i -= 1 + techniqueCount;
  }
  if (mask & MA_STATS_OPTIMAL) {
    ma_acc r[MA_MAX_TECHNIQUES];
    MA_UNROLL
    for (int k = 0; k < MA_MAX_TECHNIQUES; ++k) r[k] = (ma_acc)(s.pdfs[k] * s.invP);
    ma_acc g[3] = {(ma_acc)(s.fr * s.invP), (ma_acc)(s.fg * s.invP), (ma_acc)(s.fb * s.invP)};
    int entry = 0;
    MA_UNROLL
    for (int row = 0; row < techniqueCount; ++row) {
      MA_UNROLL
      for (int col = row; col < techniqueCount; ++col) value = i == entry++ ? r[row] * r[col] : value;
    }
    MA_UNROLL
    for (int ch = 0; ch < 3; ++ch) {
      MA_UNROLL
      for (int k = 0; k < techniqueCount; ++k) value = i == entry++ ? g[ch] * r[k] : value;
    }
  }
  return value;
}

// What a stored sample keeps of f: the root mean square of its channels (channelRms),
// so that the allocations that weigh stored samples minimise the error over RGB, not
// the luminance's alone (docs/results.md, "The allocation's colour"); with [Kon19]'s
// optimal weights (MA_STATS_OPTIMAL) its luminance, in which their retargeted sums
// take each technique's colour share from the running sums (docs/methods.md).
MA_FN float storedSampleValue(int statsMask, SampleContribution c) {
  return (statsMask & MA_STATS_OPTIMAL) ? c.y : channelRms(c.fr, c.fg, c.fb);
}

// Stored samples for the allocations that need every sample: linear with [SS23] eq. 19
// keeps them all; the grid searches of exact and oracle (kernels/gridsearch.cl) keep
// running sums and need only those taken since the previous search. Blocked by 16
// pixels for float16 loads: value q of the pixel's sample in slot i is at
// ((block·capacity + i)(C + 2) + q)·16 + lane, with q = 0 the column that drew it, 1
// its value f (storedSampleValue), 2 + l the pdf of column l.
//
// The columns are the pdfs an allocation weighs: one per technique, or, with share
// columns S > 0 (the optimal pdf's bank, for the grid search's rule (b)), the envmap's
// pdf under each of the S shares of the pixel's BRDF bin, then the other techniques.
// A combination of the grid then weighs α_0 in the column of the share that a stage of
// that α_0 samples with, and judges it by the pdf that stage would run.
#define MA_STORED_COLUMNS(techniqueCount, shareColumns) \
  ((shareColumns) > 0 ? (shareColumns) + (techniqueCount)-1 : (techniqueCount))
#define MA_SAMPLE_RECORD_FLOATS(columns) ((columns) + 2)
MA_FN int storedSampleIndex(int pixel, int i, int q, int capacity, int columns) {
  return (((pixel / 16) * capacity + i) * MA_SAMPLE_RECORD_FLOATS(columns) + q) * 16 + pixel % 16;
}

// Where a lane stores a sample that is not kept (a surplus sample of its work-group's
// pass, a padding work-item): a spare record after the buffer's blocks, from float
// `spare` on. Every lane then stores, and the store needs no mask: a masked scatter,
// which AVX2 lacks, keeps PoCL from vectorising the loop around it (docs/pocl.md).
MA_FN int spareSampleIndex(int spare, int q, int lane) { return spare + q * 16 + lane % 16; }

// The technique whose pdf column l holds.
MA_FN int techniqueOfColumn(int l, int shareColumns) {
  return shareColumns > 0 ? (l < shareColumns ? 0 : l - shareColumns + 1) : l;
}

// The column of the pdf that drew sample s.
MA_FN int storedColumn(SampleContribution s, int shareColumns) {
  return shareColumns > 0 ? (s.technique == 0 ? s.share : shareColumns + s.technique - 1) : s.technique;
}

// Column l's pdf at sample s.
MA_FN float storedPdf(SampleContribution s, int shareColumns, int l) {
  int technique = techniqueOfColumn(l, shareColumns);
  float share = l == 0 ? s.sharePdfs[0] : (l == 1 ? s.sharePdfs[1] : s.sharePdfs[2]);
  float pdf = technique == 0 ? s.pdfs[0] : (technique == 1 ? s.pdfs[1] : s.pdfs[2]);
  return shareColumns > 0 && l < shareColumns ? share : pdf;
}

#endif
