// The lat-long environment map: radiance lookup, its sampling pdf (∝ luminance ×
// sin θ per texel, uniform in (φ, θ) inside the texel) and the two samplers with that
// same pdf: an O(1) alias table and marginal/conditional CDFs with binary searches.
// With the optimal pdf ([Kar19] eq. 9), a bank of tables over blocks of texels, one
// per BRDF bin and envmap share, or the pixel's own table (kernels/pixel_optimal.h)
// picks the block, and the plain pdf the texel in it.
// Host side: host/scene/Envmap.h, host/distributions/EnvmapDistribution.h,
// host/distributions/OptimalBank.h.
#include "namespace_check.h"
#ifndef MA_ENVMAP_H
#define MA_ENVMAP_H
#include "common.h"
#include "fastmath.h"
#include "pixel_layout.h"
#include "rng.h"

// Row 0 is the zenith: texel (col, row) covers φ ∈ 2π[col, col+1)/W and
// θ ∈ π[row, row+1)/H, with z up.
//
// The optimal pdf's bank (bankShares > 0) lays the same buffers out differently:
// texels[4t + 3] is the texel's probability within its block; aliasTable starts with
// each block's alias table over its 2^L × 2^L slots (both samplers draw the texel in
// the block with it), then, for the alias sampler, each entry's alias table over the
// blocks; cdfTable holds, for the CDF sampler, each entry's CDFs over the blocks;
// blockProbs each entry's probability of each block.
typedef struct {
  MA_GLOBAL const float* texels;        // per texel: R, G, B, probability of the texel
  MA_GLOBAL const float* cdfTable;      // CDF: marginal (H+1) then conditionals H×(W+1)
  MA_GLOBAL const ma_uint* aliasTable;  // alias: per bucket, acceptance probability bits and alias
  int width, height;
  int useCdf;
  int cdfStepsRow, cdfStepsCol;       // ceil(log2(H)), ceil(log2(W)) (bank: of the blocks): fixed-step searches
  float coskExponent;                 // ≥ 0: analytic radiance cos^K θ on the upper hemisphere ([HS14] App. D)
  int bankShares;                     // the bank's shares C_i = (i+1)/(bankShares+1) per BRDF bin; 0: no bank
  int blockLog2;                      // its blocks are 2^L × 2^L texels
  MA_GLOBAL const float* blockProbs;  // per entry, per block: the probability of drawing the block
  int brdfBin;                        // the pixel's BRDF bin: its row of the bank
  int bankEntry;                      // the entry its stage samples with (bankEntryOf)
  // The optimal pdf per pixel (kernels/pixel_optimal.h), in the bank's layout of texels
  // and blocks: > 0, the blocks (cells) its CDF runs over; blockProbs then holds the
  // cells (MA_CELL_FLOATS each), not probabilities.
  int pixelCells;
  MA_LOCAL const int* pixelCdf;  // the pixel's CDF over its cells, entry p at pixelCdf[p · pixelCdfStride], as float
                                 // bits, in the CDF's order (kernels/pixel_layout.h, cdfPositionOfCell)
  int pixelCdfStride;
  int pixelCdfSteps;  // ceil(log2(pixelCells)): searchPixelCdf's steps
} EnvmapView;

typedef struct {
  float r, g, b;
  float pdf;  // solid-angle pdf of envmap sampling
} EnvmapHit;

MA_FN MaVec3 latLongDirection(float u, float v) {
  MaSinCos theta = sinCos2Pi(0.5f * v);
  MaSinCos phi = sinCos2Pi(u);
  // y as an fma, the same product (docs/pocl.md, rule 8; frameToWorld): θ's and φ's
  // sines and cosines, paired by the SLP vectoriser, kept the envmap technique's sample
  // loop scalar on haswell.
  return makeVec3(theta.s * phi.c, ma_fma(theta.s, phi.s, 0.0f), theta.c);
}

MA_FN int texelOfDirection(EnvmapView env, MaVec3 w) {
  float theta = fastAcos(w.z);
  float phi = fastAtan2Positive(w.y, w.x);
  int row = (int)(theta * ((float)env.height * MA_INV_PI));
  int col = (int)(phi * ((float)env.width * (0.5f * MA_INV_PI)));
  row = row < 0 ? 0 : (row >= env.height ? env.height - 1 : row);
  col = col < 0 ? 0 : (col >= env.width ? env.width - 1 : col);
  return row * env.width + col;
}

// ⌊i / n⌋ for 0 ≤ i < 2^30 and 1 ≤ n < 2^24 with i/n < 2^22, exact: the float quotient
// is within one of it (three roundings of 2^-24 each), and one step each way corrects it.
// x86 has no vector integer division: LLVM scalarises it, one division per lane, inside
// the vectorised sample loop (docs/pocl.md, "How misalloc's kernels apply them").
MA_FN int rowOfIndex(int i, int n) {
  int q = (int)((float)i / (float)n);
  q -= q * n > i ? 1 : 0;
  q += (q + 1) * n <= i ? 1 : 0;
  return q;
}

MA_FN int blocksAcross(EnvmapView env) { return (env.width + (1 << env.blockLog2) - 1) >> env.blockLog2; }
MA_FN int blocksDown(EnvmapView env) { return (env.height + (1 << env.blockLog2) - 1) >> env.blockLog2; }

MA_FN int blockOfTexel(EnvmapView env, int t) {
  int row = rowOfIndex(t, env.width);
  int col = t - row * env.width;
  return (row >> env.blockLog2) * blocksAcross(env) + (col >> env.blockLog2);
}

// The share C_i = (i+1)/(shares+1) nearest an envmap fraction α_0.
MA_FN int bankShareOf(int shares, float envmapFraction) {
  int share = (int)(envmapFraction * (float)(shares + 1) + 0.5f) - 1;
  return share < 0 ? 0 : (share >= shares ? shares - 1 : share);
}

// The pixel's stage samples with the entry of its BRDF bin whose share C is nearest
// the stage's envmap fraction α_0: [Kar19] eq. 9 for the C that is actually run.
MA_FN int bankEntryOf(EnvmapView env, float envmapFraction) {
  return env.brdfBin * env.bankShares + bankShareOf(env.bankShares, envmapFraction);
}

MA_FN float pixelCdfAt(EnvmapView env, int p) { return ma_as_float((ma_uint)env.pixelCdf[p * env.pixelCdfStride]); }

// The probability that the pixel's CDF draws cell c, at its position in the CDF's order
// (kernels/pixel_layout.h, cdfPositionOfCell). The entries lie on uniformFloat's grid
// (kernels/pixel_optimal.h), so the difference is exact and is the probability that
// searchPixelCdf returns c.
MA_FN float pixelCellProbability(EnvmapView env, int c) {
  int p = cdfPositionOfCell(env.pixelCells, c);
  return pixelCdfAt(env, p + 1) - pixelCdfAt(env, p);
}

// The most cells the pixel's CDF may have: 64 × 32 (kMaxPixelCellsAcross), which
// searchPixelCdf reaches in 11 of its 16 steps.
#define MA_MAX_PIXEL_CELLS 2048

// A fixed-step binary search's steps written out as straight code, STEP(i) for each i:
// a loop left in the sample loop, unrolled or not, keeps PoCL's sample loop scalar
// (2–3× the time per sample; docs/pocl.md, rule 3). A step at or past the search's own
// count is folded away where that count is a compile-time constant (the kernel's).
#define MA_SEARCH_STEPS_8(STEP) STEP(0) STEP(1) STEP(2) STEP(3) STEP(4) STEP(5) STEP(6) STEP(7)
#define MA_SEARCH_STEPS_16(STEP) \
  MA_SEARCH_STEPS_8(STEP) STEP(8) STEP(9) STEP(10) STEP(11) STEP(12) STEP(13) STEP(14) STEP(15)

// One step of searchPixelCdf, where the search has steps left.
MA_FN void pixelCdfStep(EnvmapView env, int stepIndex, float u, int* base, int* n) {
  int step = *n >> 1;
  int take = stepIndex < env.pixelCdfSteps && pixelCdfAt(env, *base + step) <= u;
  *base = take ? *base + step : *base;
  *n = stepIndex < env.pixelCdfSteps ? *n - step : *n;
}

// The cell at the last position p with cdf[p] ≤ u: searchCdf over the pixel's CDF. A
// cell of probability 0 is never returned.
MA_FN int searchPixelCdf(EnvmapView env, float u) {
  int base = 0, n = env.pixelCells;
#define MA_PIXEL_CDF_STEP(i) pixelCdfStep(env, i, u, &base, &n);
  MA_SEARCH_STEPS_16(MA_PIXEL_CDF_STEP)
#undef MA_PIXEL_CDF_STEP
  return cellAtCdfPosition(env.pixelCells, base);
}

// The factor of texel t's probability that its block carries: the probability of
// drawing the block, from the bank's entry or the pixel's own CDF.
MA_FN float blockProbability(EnvmapView env, int t) {
  int block = blockOfTexel(env, t);
  return env.pixelCells > 0 ? pixelCellProbability(env, block)
                            : env.blockProbs[env.bankEntry * blocksAcross(env) * blocksDown(env) + block];
}

MA_FN int drawsBlocks(EnvmapView env) { return env.bankShares > 0 || env.pixelCells > 0; }

// The probability that envmap sampling draws texel t, from p, its probability within
// its block (the optimal pdf's bank or per pixel) or in the map.
MA_FN float bankedProbability(EnvmapView env, int t, float p) {
  return drawsBlocks(env) ? p * blockProbability(env, t) : p;
}

// The probability that envmap sampling draws texel t.
MA_FN float texelProbability(EnvmapView env, int t) { return bankedProbability(env, t, env.texels[4 * t + 3]); }

// A texel picked with probability P is spread uniformly over its (u, v) area 1/(WH),
// and dω = 2π² sin θ du dv, so p(ω) = P W H / (2π² sin θ).
MA_FN float envmapPdfOfTexel(EnvmapView env, float texelProbability, float sinTheta) {
  return texelProbability * (float)env.width * (float)env.height / (2.0f * MA_PI * MA_PI * ma_max(sinTheta, 1e-7f));
}

// The most shares a bank has (host/distributions/OptimalBank.h, OptimalBankOptions).
#define MA_MAX_BANK_SHARES 3

// The envmap's pdf at ω in texel t under every share of the pixel's BRDF bin, each as
// envmapTexelHit computes it for that share's entry: what a stage of each share would
// sample ω with. The grid search weighs each α_0 with the share that a stage of that
// α_0 samples with (kernels/stats.h, stored columns). Shares past bankShares are 0.
MA_FN void bankSharePdfs(EnvmapView env, int t, float sinTheta, float* pdfs) {
  float p = env.texels[4 * t + 3];
  MA_UNROLL
  for (int s = 0; s < MA_MAX_BANK_SHARES; ++s) {
    env.bankEntry = env.brdfBin * env.bankShares + s;
    pdfs[s] = s < env.bankShares ? envmapPdfOfTexel(env, bankedProbability(env, t, p), sinTheta) : 0.0f;
  }
}

// Radiance and pdf at ω inside texel t: the texel's four words as two 64-bit reads.
MA_FN EnvmapHit envmapTexelHit(EnvmapView env, int t, MaVec3 w) {
  ma_ulong rg = ma_load64(env.texels, 2 * t), bp = ma_load64(env.texels, 2 * t + 1);
  EnvmapHit hit;
  if (env.coskExponent >= 0.0f) {
    hit.r = hit.g = hit.b = w.z > 0.0f ? fastPow(w.z, env.coskExponent) : 0.0f;
  } else {
    hit.r = ma_as_float(lowWord(rg));
    hit.g = ma_as_float(highWord(rg));
    hit.b = ma_as_float(lowWord(bp));
  }
  hit.pdf = envmapPdfOfTexel(env, bankedProbability(env, t, ma_as_float(highWord(bp))), ma_sqrt(w.x * w.x + w.y * w.y));
  return hit;
}

MA_FN EnvmapHit envmapLookup(EnvmapView env, MaVec3 w) { return envmapTexelHit(env, texelOfDirection(env, w), w); }

// Vose alias table. The bucket comes from a full 32-bit integer and the coin from an
// independent uniform: one 24-bit uniform for both is biased for large tables.
MA_FN int sampleAliasTable(MA_GLOBAL const ma_uint* table, ma_uint buckets, ma_uint bucketBits, float coin) {
  ma_uint bucket = mulHi(bucketBits, buckets);
  ma_ulong entry = ma_load64(table, (int)bucket);  // acceptance bits, alias
  return coin < ma_as_float(lowWord(entry)) ? (int)bucket : (int)highWord(entry);
}

// The most steps searchCdf takes: a CDF over at most 65536 rows or columns.
#define MA_MAX_CDF_STEPS 16

// One step of searchCdf, where the search has steps left.
MA_FN void cdfStep(MA_GLOBAL const float* cdf, int stepIndex, int steps, float u, int* base, int* n) {
  int step = *n >> 1;
  int take = stepIndex < steps && cdf[*base + step] <= u;
  *base = take ? *base + step : *base;
  *n = stepIndex < steps ? *n - step : *n;
}

// The last index i in [0, n) with cdf[i] ≤ u, cdf[0] = 0 ≤ u < 1 = cdf[n], for n ≤
// 2^MA_MAX_CDF_STEPS: a branchless search of `steps` = ceil(log2(n)) steps, so every
// work-item runs the same code.
MA_FN int searchCdf(MA_GLOBAL const float* cdf, int n, int steps, float u) {
  int base = 0;
#define MA_CDF_STEP(i) cdfStep(cdf, i, steps, u, &base, &n);
  MA_SEARCH_STEPS_16(MA_CDF_STEP)
#undef MA_CDF_STEP
  return base;
}

// A cell of a width × height grid from its marginal and conditional CDFs.
MA_FN int sampleCdfTable(EnvmapView env, MA_GLOBAL const float* marginal, int width, int height, float uRow,
                         float uCol) {
  int row = searchCdf(marginal, height, env.cdfStepsRow, uRow);
  MA_GLOBAL const float* conditional = marginal + (height + 1) + row * (width + 1);
  int col = searchCdf(conditional, width, env.cdfStepsCol, uCol);
  return row * width + col;
}

typedef struct {
  MaVec3 w;
  int texel;  // the texel drawn, which holds w
} EnvmapSample;

// A direction in texel t, at the jitter's place in its (u, v) square.
MA_FN EnvmapSample envmapSampleIn(EnvmapView env, int t, float jitterU, float jitterV) {
  int row = rowOfIndex(t, env.width);
  int col = t - row * env.width;
  float u = ((float)col + jitterU) / (float)env.width;
  float v = ((float)row + jitterV) / (float)env.height;
  EnvmapSample s;
  s.w = latLongDirection(u, v);
  s.texel = t;
  return s;
}

// A texel of `block` from its alias table over its 2^L × 2^L slots (`slotTables`, as
// writeBlockSlotTables lays them out): the top 2L bits of rnd.v[2] pick the slot, the
// rest are the coin, exactly uniform and independent of it. The jitter in the texel
// takes 16 bits of rnd.v[3] each. The optimal pdf's bank and the product technique
// (kernels/product.h) draw their texels so.
MA_FN EnvmapSample sampleTexelInBlock(EnvmapView env, MA_GLOBAL const ma_uint* slotTables, int block, int across,
                                      int blockLog2, MaRandom4 rnd) {
  int slotBits = 2 * blockLog2;
  MA_GLOBAL const ma_uint* slots = slotTables + 2 * (block << slotBits);
  int slot = (int)(rnd.v[2] >> (32 - slotBits));
  ma_ulong entry = ma_load64(slots, slot);  // acceptance bits, alias
  slot = uniformFloat(rnd.v[2] << slotBits) < ma_as_float(lowWord(entry)) ? slot : (int)highWord(entry);
  int blockRow = rowOfIndex(block, across);
  int row = (blockRow << blockLog2) + (slot >> blockLog2);
  int col = ((block - blockRow * across) << blockLog2) + (slot & ((1 << blockLog2) - 1));
  return envmapSampleIn(env, row * env.width + col, (float)(rnd.v[3] >> 16) * (1.0f / 65536.0f),
                        (float)(rnd.v[3] & 0xffffu) * (1.0f / 65536.0f));
}

// The bank: a block from the entry's table (rnd.v[0], v[1]), then a texel in it.
MA_FN EnvmapSample sampleEnvmapBank(EnvmapView env, MaRandom4 rnd) {
  int across = blocksAcross(env), down = blocksDown(env), blocks = across * down;
  int slotBits = 2 * env.blockLog2;
  int block = env.useCdf ? sampleCdfTable(env, env.cdfTable + env.bankEntry * ((down + 1) + down * (across + 1)),
                                          across, down, uniformFloat(rnd.v[0]), uniformFloat(rnd.v[1]))
                         : sampleAliasTable(env.aliasTable + 2 * ((blocks << slotBits) + env.bankEntry * blocks),
                                            (ma_uint)blocks, rnd.v[0], uniformFloat(rnd.v[1]));
  return sampleTexelInBlock(env, env.aliasTable, block, across, env.blockLog2, rnd);
}

// The optimal pdf per pixel: a cell from the pixel's CDF (rnd.v[0]), then a texel in it.
MA_FN EnvmapSample sampleEnvmapPixelCells(EnvmapView env, MaRandom4 rnd) {
  int block = searchPixelCdf(env, uniformFloat(rnd.v[0]));
  return sampleTexelInBlock(env, env.aliasTable, block, blocksAcross(env), env.blockLog2, rnd);
}

// The pdf of a drawn direction is that of the texel it was drawn in (as pbrt-v4's
// ImageInfiniteLight::SampleLi): envmapTexelHit then needs no texelOfDirection, whose
// inverse trigonometry and dependent gather would follow the alias table's gather.
// Both agree except where rounding puts w on a neighbouring texel's edge.
MA_FN EnvmapSample sampleEnvmap(EnvmapView env, MaRandom4 rnd) {
  if (env.bankShares > 0) return sampleEnvmapBank(env, rnd);
  if (env.pixelCells > 0) return sampleEnvmapPixelCells(env, rnd);
  int t = env.useCdf
              ? sampleCdfTable(env, env.cdfTable, env.width, env.height, uniformFloat(rnd.v[0]), uniformFloat(rnd.v[1]))
              : sampleAliasTable(env.aliasTable, (ma_uint)(env.width * env.height), rnd.v[0], uniformFloat(rnd.v[1]));
  return envmapSampleIn(env, t, uniformFloat(rnd.v[2]), uniformFloat(rnd.v[3]));
}

#endif
