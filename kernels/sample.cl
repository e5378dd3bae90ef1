// One stage of the multi-sample ([HS14] eq. 4.1) or one-sample balance-heuristic
// estimator for every pixel at once. Host side: host/sampling/Sampler.h runs it,
// host/sampling/HostSampler.cpp is its C++ reference.
//
// Compile-time options (sampleKernelOptions in host/sampling/Sampler.cpp):
// MA_TECHNIQUES (M), MA_SPLIT_BRDF, MA_USE_CDF, MA_CDF_STEPS_ROW, MA_CDF_STEPS_COL,
// MA_ANALYTIC_RADIANCE (1: the map is cos^K θ, K the argument coskExponent, so that every
// K shares one program; 0: the texels), MA_BANK_SHARES (the optimal pdf's bank,
// kernels/envmap.h; 0: none), MA_ONE_SAMPLE, MA_COUNT_INDEPENDENT, MA_RIS_CANDIDATES
// (> 0: technique 0 resamples that many envmap candidates, kernels/ris.h),
// MA_PRODUCT_TABLES, MA_PRODUCT_BLOCK_LOG2 and MA_PRODUCT_PLAIN_TEXELS (the product
// technique's tables, kernels/product.h; 0: none), MA_PIXEL_CELLS and MA_PIXEL_CDF_STEPS
// (the optimal pdf per pixel over that many blocks of texels, kernels/pixel_optimal.h;
// 0: none), MA_PRODUCT_CELLS (1: the product technique from
// those cells, kernels/product.h), MA_STATS (the
// running sums kept, kernels/stats.h), MA_STORE_SAMPLES, MA_SHARE_COLUMNS (the stored
// samples' share columns, kernels/stats.h; 0: none), MA_OPTIMAL_WEIGHTS ([Kon19]'s
// weights, from per-pixel coefficients, an argument of their own), MA_LOCAL_SIZE, and for
// samplePixelStage MA_PIXEL_LANES (0: no such kernel) with MA_GROUP_PIXELS and MA_SPLIT_LOAD64.
// Constants fold the unused techniques, sampler, estimator and statistics away.
//
// No contraction of a*b + c into fma but where the code says fma: the C++ reference is
// compiled with -ffp-contract=off too (CMakeLists.txt), so that a pixel's arithmetic is
// the same on PoCL and on the host, bit for bit (`--device cpu,host`, tests/test_devices.cpp).
// It costs PoCL nothing measurable (README, "Sampling kernel against its OpenMP peer").
#pragma OPENCL FP_CONTRACT OFF
#include "pixel_pairs.h"
#include "stats.h"

#if MA_OPTIMAL_WEIGHTS && (MA_ONE_SAMPLE || MA_COUNT_INDEPENDENT)
#error "the optimal weights are those of the multi-sample estimator"
#endif

#define STAT_SLOTS (MA_TECHNIQUES * MA_STATS_PER_TECHNIQUE(MA_STATS, MA_TECHNIQUES))
// A multi-sample stage samples each technique in a loop of its own; one-sample, one loop.
// Each runs at least techniqueLeastTurns (kernels/pixel_layout.h) turns.
#define TECHNIQUE_LOOPS (MA_ONE_SAMPLE ? 1 : MA_TECHNIQUES)
#define SAMPLE_COLUMNS MA_STORED_COLUMNS(MA_TECHNIQUES, MA_SHARE_COLUMNS)

// The per-pixel sums live in local memory, one row per sum (SUM_*, kernels/pixel_layout.h):
// PoCL then keeps nothing but the loop counter across the barrier, and nothing that its
// earlier passes could pack into short vectors, which would stop it vectorising across
// work-items.
//
// What a pixel's samples share is read from global memory once, before the sample loop,
// into one row of local memory per value (ROW_*, kernels/pixel_layout.h), as the sums:
// the loop keeps nothing across its barrier, and reads local memory at the work-item's
// index instead of global memory at the pixel's. PoCL's haswell target has no gather
// instruction, so each read at the pixel's index was one scalar load per lane
// (docs/pocl.md, "How misalloc's kernels apply them").
#define ROW_PRODUCT MA_ROW_PRODUCT(MA_OPTIMAL_WEIGHTS, MA_TECHNIQUES)
#define ROW_PIXEL_CDF MA_ROW_PIXEL_CDF(MA_OPTIMAL_WEIGHTS, MA_TECHNIQUES, MA_PRODUCT_TABLES > 0)
#define ROW_COUNT \
  MA_PIXEL_ROW_COUNT(MA_OPTIMAL_WEIGHTS, MA_TECHNIQUES, MA_PRODUCT_TABLES > 0, MA_PIXEL_CELLS, MA_PRODUCT_CELLS, \
                     MA_SHARE_COLUMNS > 0)
#define HAS_PRODUCT (MA_PRODUCT_TABLES > 0 || MA_PRODUCT_CELLS)

MA_FN ProductView productView(__global const float* productFloats, __global const uint* productWords) {
  ProductView p;
  p.floats = productFloats;
  p.words = productWords;
  p.tables = MA_PRODUCT_TABLES;
  p.blockLog2 = MA_PRODUCT_BLOCK_LOG2;
  p.plainTexels = MA_PRODUCT_PLAIN_TEXELS;
  p.pixelCells = MA_PRODUCT_CELLS;
  return p;
}

// The BRDF of the shading point at `point` (shadingPointOffset).
MA_FN PhongParams pointBrdf(__global const float* point) {
  PhongParams brdf;
  brdf.rhoD = point[ROW_RHO_D];
  brdf.rhoS = point[ROW_RHO_S];
  brdf.n = point[ROW_N];
  return brdf;
}

// Writes what a pixel's samples share into its rows: row r at pixelRows[r·rowStride + column].
MA_FN void loadPixelRows(__local int* pixelRows, int rowStride, int column, __global const float* shadingPoints,
                         __global const int* counts, __global const uint* firstIndex,
                         __global const float* coefficients, __global const float* productFloats,
                         __global const uint* productWords, int stageSamples, int pixel) {
#define PIXEL_ROW(row) pixelRows[(row)*rowStride + column]
  StageCounts pixelCounts = loadStageCounts(counts, firstIndex, pixel, MA_TECHNIQUES, stageSamples, MA_ONE_SAMPLE,
                                            MA_COUNT_INDEPENDENT, MA_RIS_CANDIDATES);
  __global const float* point = shadingPoints + shadingPointOffset(pixel);
  // Not unrolled: unrolled, its adjacent reads are paired by LLVM's SLP vectoriser on
  // PoCL's haswell target, and the work-item loop stays scalar (docs/pocl.md, rule 8).
  for (int r = 0; r < MA_SHADING_POINT_WORDS; ++r) PIXEL_ROW(r) = as_int(point[r]);
  int countValues[ROW_COEFFICIENTS - ROW_N0] = {pixelCounts.n0,          pixelCounts.n1,
                                                pixelCounts.n2,          (int)pixelCounts.first0,
                                                (int)pixelCounts.first1, (int)pixelCounts.first2};
  MA_UNROLL
  for (int r = ROW_N0; r < ROW_COEFFICIENTS; ++r) PIXEL_ROW(r) = countValues[r - ROW_N0];
#if MA_OPTIMAL_WEIGHTS
  MA_UNROLL
  for (int r = 0; r < 3 * MA_TECHNIQUES; ++r)
    PIXEL_ROW(ROW_COEFFICIENTS + r) = as_int(coefficients[coefficientsOffset(pixel, MA_TECHNIQUES) + r]);
#endif
#if MA_PRODUCT_TABLES > 0
  ProductMixture mixture = productMixture(productView(productFloats, productWords), pointBrdf(point));
  PIXEL_ROW(ROW_PRODUCT) = as_int(mixture.diffuse);
  PIXEL_ROW(ROW_PRODUCT + 1) = as_int(mixture.specular);
  PIXEL_ROW(ROW_PRODUCT + 2) = mixture.specularTable;
#endif
#undef PIXEL_ROW
}

// What the optimal pdf per pixel is built from (kernels/pixel_pairs.h), read from the
// pixel's rows.
MA_FN PixelCdfInputs pixelCdfInputs(__local const int* pixelRows, int rowStride, int column, int stageSamples) {
#define ROW_FLOAT(row) as_float(pixelRows[(row)*rowStride + column])
  PhongParams brdf;
  brdf.rhoD = ROW_FLOAT(ROW_RHO_D);
  brdf.rhoS = ROW_FLOAT(ROW_RHO_S);
  brdf.n = ROW_FLOAT(ROW_N);
  StageCounts c;
  c.n0 = pixelRows[ROW_N0 * rowStride + column];
  c.n1 = pixelRows[ROW_N1 * rowStride + column];
  c.stageSamples = stageSamples;
  return cdfInputsOf(brdf, makeVec3(ROW_FLOAT(ROW_NORMAL_X), ROW_FLOAT(ROW_NORMAL_Y), ROW_FLOAT(ROW_NORMAL_Z)),
                     makeVec3(ROW_FLOAT(ROW_MIRROR_X), ROW_FLOAT(ROW_MIRROR_Y), ROW_FLOAT(ROW_MIRROR_Z)), c,
                     HAS_PRODUCT);
#undef ROW_FLOAT
}

// Pixel q's table inputs and whether it takes samples, read from global memory, where
// its stage writes them.
MA_FN PixelCdfInputs storedCdfInputs(__global const float* shadingPoints, __global const int* counts,
                                     __global const uint* firstIndex, int stageSamples, int q, int* samples) {
  __global const float* point = shadingPoints + shadingPointOffset(q);
  StageCounts c = loadStageCounts(counts, firstIndex, q, MA_TECHNIQUES, stageSamples, MA_ONE_SAMPLE,
                                  MA_COUNT_INDEPENDENT, MA_RIS_CANDIDATES);
  *samples = pixelStageSamples(c) > 0;
  return cdfInputsOf(pointBrdf(point), makeVec3(point[ROW_NORMAL_X], point[ROW_NORMAL_Y], point[ROW_NORMAL_Z]),
                     makeVec3(point[ROW_MIRROR_X], point[ROW_MIRROR_Y], point[ROW_MIRROR_Z]), c, HAS_PRODUCT);
}

// The table that `pixel` samples (kernels/pixel_pairs.h), given its own inputs: its
// quad's, its pair's or its own.
MA_FN TableGroup pixelTableGroup(PixelCdfInputs own, __global const float* shadingPoints, __global const int* counts,
                                 __global const uint* firstIndex, int stageSamples, int pixel, int imageWidth) {
  int x = pixel % imageWidth, row = pixel - x, partner = pairPartner(x);
  if (partner >= imageWidth) return ownTable(pixel, own);
  int partnerSamples, aSamples, bSamples;
  PixelCdfInputs p = storedCdfInputs(shadingPoints, counts, firstIndex, stageSamples, row + partner, &partnerSamples);
  PairTable pair = pairTableOf(own, p, partnerSamples, MA_PIXEL_CELLS);
  if (!pair.shares) return ownTable(pixel, own);
  if (quadPlaces(x, imageWidth) < 4) return pairGroup(pixel, x, pair);
  int other = row + otherPairFirst(x);
  PixelCdfInputs a = storedCdfInputs(shadingPoints, counts, firstIndex, stageSamples, other, &aSamples);
  PixelCdfInputs b = storedCdfInputs(shadingPoints, counts, firstIndex, stageSamples, other + 1, &bSamples);
  return quadGroup(pixel, x, pair, pairTableOf(a, b, aSamples && bSamples, MA_PIXEL_CELLS), MA_PIXEL_CELLS);
}

// The one-sample estimator's pass: the stage's samples, none for the background
// (pixelStageSamples).
MA_FN int oneSamplePassSamples(__local const int* pixelRows, int rowStride, int column) {
  return pixelRows[ROW_N0 * rowStride + column] + pixelRows[ROW_N1 * rowStride + column] +
         pixelRows[ROW_N2 * rowStride + column];
}

// The unit vector at rows row, row + 1, row + 2, and the basis about it.
MA_FN MaFrame frameOfRows(__local const int* pixelRows, int rowStride, int column, int row) {
#define ROW_FLOAT(r) as_float(pixelRows[(row + (r)) * rowStride + column])
  return frameAbout(makeVec3(ROW_FLOAT(0), ROW_FLOAT(1), ROW_FLOAT(2)));
#undef ROW_FLOAT
}

// Sample j of `technique`'s samples (one-sample: of the stage), from the pixel's rows
// and its per-pixel CDFs (row r at cdfRows[r · cdfStride]). The envmap tables are read
// where the sample falls: they are the gathers that remain.
// The random numbers are keyed on the image's pixel firstPixel + pixel: a band of an
// image's rows (host/render/Band.h) draws the samples the whole image's render draws.
MA_FN SampleContribution sampleOfPixel(__global const float* texels, __global const float* cdfTable,
                                       __global const uint* aliasTable, __global const float* blockProbs,
                                       __global const float* productFloats, __global const uint* productWords,
                                       int width, int height, float coskExponent, int blockLog2,
                                       __local const int* pixelRows, int rowStride, int column,
                                       __local const int* cdfRows, int cdfStride, int stageSamples, uint seedLo,
                                       uint seedHi, int firstPixel, int pixel, int technique, int j) {
#define PIXEL_ROW(row) pixelRows[(row)*rowStride + column]
  EnvmapView env;
  env.texels = texels;
  env.cdfTable = cdfTable;
  env.aliasTable = aliasTable;
  env.width = width;
  env.height = height;
  env.useCdf = MA_USE_CDF;
  env.cdfStepsRow = MA_CDF_STEPS_ROW;
  env.cdfStepsCol = MA_CDF_STEPS_COL;
  env.coskExponent = MA_ANALYTIC_RADIANCE ? coskExponent : -1.0f;
  env.bankShares = MA_BANK_SHARES;
  env.blockLog2 = blockLog2;
  env.blockProbs = blockProbs;
  env.brdfBin = (int)as_float(PIXEL_ROW(ROW_BRDF_BIN));
  env.bankEntry = 0;
  env.pixelCells = MA_PIXEL_CELLS;
  env.pixelCdf = cdfRows;
  env.pixelCdfStride = cdfStride;
  env.pixelCdfSteps = MA_PIXEL_CDF_STEPS;

  TechniqueSet ts;
  ts.techniqueCount = MA_TECHNIQUES;
  ts.splitBrdf = MA_SPLIT_BRDF;
  ts.product = productView(productFloats, productWords);
  ts.productMixture.diffuse = MA_PRODUCT_TABLES > 0 ? as_float(PIXEL_ROW(ROW_PRODUCT)) : 0.0f;
  ts.productMixture.specular = MA_PRODUCT_TABLES > 0 ? as_float(PIXEL_ROW(ROW_PRODUCT + 1)) : 0.0f;
  ts.productMixture.specularTable = MA_PRODUCT_TABLES > 0 ? PIXEL_ROW(ROW_PRODUCT + 2) : 0;
  ts.sharePdfs = MA_SHARE_COLUMNS > 0;

  ShadingPoint sp;
  sp.brdf.rhoD = as_float(PIXEL_ROW(ROW_RHO_D));
  sp.brdf.rhoS = as_float(PIXEL_ROW(ROW_RHO_S));
  sp.brdf.n = as_float(PIXEL_ROW(ROW_N));
  sp.normalFrame = frameOfRows(pixelRows, rowStride, column, ROW_NORMAL_X);
  sp.mirrorFrame = frameOfRows(pixelRows, rowStride, column, ROW_MIRROR_X);

  StageCounts c;
  c.techniqueCount = MA_TECHNIQUES;
  c.stageSamples = stageSamples;
  c.oneSample = MA_ONE_SAMPLE;
  c.countIndependent = MA_COUNT_INDEPENDENT;
  c.risCandidates = MA_RIS_CANDIDATES;
  c.n0 = PIXEL_ROW(ROW_N0);
  c.n1 = PIXEL_ROW(ROW_N1);
  c.n2 = PIXEL_ROW(ROW_N2);
  c.first0 = (uint)PIXEL_ROW(ROW_FIRST0);
  c.first1 = (uint)PIXEL_ROW(ROW_FIRST1);
  c.first2 = (uint)PIXEL_ROW(ROW_FIRST2);
#if MA_ONE_SAMPLE
  return takeStageSample(ts, env, sp, c, j, seedLo, seedHi, (uint)(firstPixel + pixel));
#else
  SampleContribution s = takeTechniqueSample(ts, env, sp, c, technique, firstIndexOf(c, technique) + (uint)j, seedLo,
                                             seedHi, (uint)(firstPixel + pixel));
#if MA_OPTIMAL_WEIGHTS
  OptimalCoefficients a;
  MA_UNROLL
  for (int ch = 0; ch < 3; ++ch) {
    MA_UNROLL
    for (int k = 0; k < MA_MAX_TECHNIQUES; ++k)
      a.a[ch][k] = k < MA_TECHNIQUES ? as_float(PIXEL_ROW(ROW_COEFFICIENTS + ch * MA_TECHNIQUES + k)) : 0.0f;
  }
  s = withOptimalWeights(s, c, a);
#endif
  return s;
#endif
#undef PIXEL_ROW
}

// Stores sample c of the pixel in slot i (kernels/stats.h), or, where it is not `kept`,
// in the lane's spare record: every lane stores, unmasked.
MA_FN void storeSample(__global float* samples, SampleContribution c, int kept, int pixel, int i, int sampleCapacity,
                       int spareSamples, int lane) {
#define STORED_AT(q) \
  (kept ? storedSampleIndex(pixel, i, (q), sampleCapacity, SAMPLE_COLUMNS) : spareSampleIndex(spareSamples, (q), lane))
  samples[STORED_AT(0)] = (float)storedColumn(c, MA_SHARE_COLUMNS);
  samples[STORED_AT(1)] = storedSampleValue(MA_STATS, c);
  MA_UNROLL
  for (int l = 0; l < SAMPLE_COLUMNS; ++l) samples[STORED_AT(2 + l)] = storedPdf(c, MA_SHARE_COLUMNS, l);
#undef STORED_AT
}

// The arguments of both sampling kernels: the host binds them once (Sampler::runPixels).
// --weights optimal: a_{c,k} at coefficientsOffset(pixel, M) + c·M + k (kernels/pixel_layout.h).
#if MA_OPTIMAL_WEIGHTS
#define MA_OPTIONAL_PARAMETERS , __global const float* coefficients
#define MA_COEFFICIENTS coefficients
#else
#define MA_OPTIONAL_PARAMETERS
#define MA_COEFFICIENTS ((__global const float*)0)
#endif
// blockLog2: the bank's and the per-pixel cells' blocks are 2^blockLog2 texels across,
// a shift of the map's size: an argument, so that maps of every size share a program.
#define MA_SAMPLE_STAGE_PARAMETERS                                                                                  \
  __global const float *texels, __global const float *cdfTable, __global const uint *aliasTable,                    \
      __global const float *blockProbs, __global const float *productFloats, __global const uint *productWords,     \
      int width, int height, float coskExponent, int blockLog2, __global const float *shadingPoints,                \
      __global const int *counts, __global const uint *firstIndex, int stageSamples, uint seedLo, uint seedHi,      \
      int firstPixel, int pixelCount, int imageWidth, __global const int *pixelOrder, __global ma_acc *estimate,    \
      __global ma_acc *moments, __global ma_acc *stats, __global float *samples, int firstSlot, int sampleCapacity, \
      int spareSamples MA_OPTIONAL_PARAMETERS

__kernel __attribute__((reqd_work_group_size(MA_LOCAL_SIZE, 1, 1))) void sampleStage(MA_SAMPLE_STAGE_PARAMETERS) {
  __local ma_acc sums[SUM_COUNT][MA_LOCAL_SIZE];
  __local ma_acc running[STAT_SLOTS > 0 ? STAT_SLOTS : 1][MA_LOCAL_SIZE];
  int gid = (int)get_global_id(0), lid = (int)get_local_id(0);
  // Pixels in the host's order (coherentPixelOrder): work-groups of like counts. Padding
  // work-items run the loop too: the barrier needs every work-item.
  int pixel = pixelOrder[gid < pixelCount ? gid : pixelCount - 1];
  for (int s = 0; s < SUM_COUNT; ++s) sums[s][lid] = 0;
  // The running sums carry over from earlier stages.
  for (int s = 0; s < STAT_SLOTS; ++s) running[s][lid] = stats[statsOffset(pixel, STAT_SLOTS) + s];
  __local int pixelRows[ROW_COUNT * MA_LOCAL_SIZE];
  loadPixelRows(pixelRows, MA_LOCAL_SIZE, lid, shadingPoints, counts, firstIndex, MA_COEFFICIENTS, productFloats,
                productWords, stageSamples, pixel);
#if MA_PIXEL_CELLS > 0
  // The background takes no samples and needs no table.
  if (oneSamplePassSamples(pixelRows, MA_LOCAL_SIZE, lid) > 0) {
    PixelCdfInputs own = pixelCdfInputs(pixelRows, MA_LOCAL_SIZE, lid, stageSamples);
    PixelCdfInputs in =
        pixelTableGroup(own, shadingPoints, counts, firstIndex, stageSamples, pixel, imageWidth).inputs;
    buildPixelOptimalCdf(blockProbs, MA_PIXEL_CELLS, in.brdf, in.normal, in.mirror, in.envmapShare, in.brdfCovers,
                         MA_SHARE_COLUMNS > 0, MA_PRODUCT_CELLS, pixelRows + ROW_PIXEL_CDF * MA_LOCAL_SIZE + lid,
                         MA_LOCAL_SIZE);
  }
#endif
  // Multi-sample: technique k's n_k samples in turn, the order of takeStageSample, so
  // that the technique is a constant in the loop and the vectorised code runs its
  // sampler only. A work-group runs its largest n_k; the other work-items' surplus
  // samples are not counted. One-sample: one pass of N samples.
  __local int passCounts[MA_LOCAL_SIZE];
  int start = 0;  // the pass's first sample in the stage
  MA_UNROLL
  for (int k = 0; k < TECHNIQUE_LOOPS; ++k) {
    int n = MA_ONE_SAMPLE ? oneSamplePassSamples(pixelRows, MA_LOCAL_SIZE, lid)
                          : pixelRows[(ROW_N0 + k) * MA_LOCAL_SIZE + lid];
    passCounts[lid] = n;
    barrier(CLK_LOCAL_MEM_FENCE);
    int passSamples = 0;
    MA_UNROLL
    for (int l = 0; l < MA_LOCAL_SIZE; ++l) passSamples = max(passSamples, passCounts[l]);
    barrier(CLK_LOCAL_MEM_FENCE);  // every work-item has read passCounts before the next pass writes it
    // A loop around a barrier that may run no turn makes PoCL copy each later
    // technique's loop once per way around it (docs/pocl.md, rule 12): a technique
    // between the first and the last runs at least one turn, uncounted where the
    // work-group's n are all 0.
    int jk = 0;
    if (passSamples > 0 || techniqueLeastTurns(k, TECHNIQUE_LOOPS) > 0) do {
      SampleContribution c =
          sampleOfPixel(texels, cdfTable, aliasTable, blockProbs, productFloats, productWords, width, height,
                        coskExponent, blockLog2, pixelRows, MA_LOCAL_SIZE, lid,
                        pixelRows + ROW_PIXEL_CDF * MA_LOCAL_SIZE + lid, MA_LOCAL_SIZE, stageSamples, seedLo, seedHi,
                        firstPixel, pixel, k, jk);
      int counted = jk < n, j = start + jk;
      ma_acc w = counted ? (ma_acc)c.w : 0, ww = w * w;
      sums[SUM_R][lid] += counted ? (ma_acc)c.r : 0;
      sums[SUM_G][lid] += counted ? (ma_acc)c.g : 0;
      sums[SUM_B][lid] += counted ? (ma_acc)c.b : 0;
      sums[SUM_W0][lid] += c.technique == 0 ? w : 0;
      sums[SUM_WW0][lid] += c.technique == 0 ? ww : 0;
      sums[SUM_W1][lid] += c.technique == 1 ? w : 0;
      sums[SUM_WW1][lid] += c.technique == 1 ? ww : 0;
      if (MA_TECHNIQUES > 2) {
        sums[SUM_W2][lid] += c.technique == 2 ? w : 0;
        sums[SUM_WW2][lid] += c.technique == 2 ? ww : 0;
      }
      MA_UNROLL
      for (int s = 0; s < STAT_SLOTS; ++s) {
        int perTechnique = MA_STATS_PER_TECHNIQUE(MA_STATS, MA_TECHNIQUES);
        running[s][lid] +=
            counted && c.technique == s / perTechnique ? statValue(MA_STATS, MA_TECHNIQUES, s % perTechnique, c) : 0;
      }
      if (MA_STORE_SAMPLES)
        storeSample(samples, c, counted && gid < pixelCount, pixel, firstSlot + j, sampleCapacity, spareSamples, lid);
      barrier(CLK_LOCAL_MEM_FENCE);  // keeps PoCL's work-item loop innermost: vectorised across pixels
      ++jk;
    } while (jk < passSamples);
    start += n;
  }
  if (gid < pixelCount) {
    __global ma_acc* e = estimate + estimateOffset(pixel);
    e[0] = sums[SUM_R][lid];
    e[1] = sums[SUM_G][lid];
    e[2] = sums[SUM_B][lid];
    __global ma_acc* m = moments + momentsOffset(pixel, MA_TECHNIQUES);
    m[0] = sums[SUM_W0][lid];
    m[1] = sums[SUM_WW0][lid];
    m[2] = sums[SUM_W1][lid];
    m[3] = sums[SUM_WW1][lid];
    if (MA_TECHNIQUES > 2) {
      m[4] = sums[SUM_W2][lid];
      m[5] = sums[SUM_WW2][lid];
    }
    for (int s = 0; s < STAT_SLOTS; ++s) stats[statsOffset(pixel, STAT_SLOTS) + s] = running[s][lid];
  }
}

#if MA_PIXEL_LANES > 0 && MA_STATS == 0
// The same stage on a CPU, a work-group of L = MA_PIXEL_LANES lanes (the float vector
// width) for P = MA_GROUP_PIXELS ≤ L pixels (L, or fewer where their tables would not
// fit local memory: host/sampling/Sampler.h, pixelStageGroupPixels). First lane l
// builds pixel l's table (the C++ reference's buildPixelOptimalCdf), unless a lane
// before it builds the table that it samples (its pair's or quad's,
// kernels/pixel_pairs.h): the lanes read
// each cell at one address, and PoCL vectorises the build's first pass across cells.
// Then the lanes sample the pixels one at a time: lane l takes samples l, L + l,
// 2L + l, ... of each technique, so that PoCL vectorises across a pixel's samples.
// Nothing 64-bit is loaded, stored or carried in the sample loop, which would cap
// LLVM's width at 4 on AVX2 (docs/pocl.md, rule 10): each sample's terms go to local
// memory in float, and lane 0 adds a chunk of them in the C++ reference's order
// (addContribution), which keeps the sums bit for bit its sums. Each lane stores its own
// samples (MA_STORE_SAMPLES, exact's pilot); running sums stay with sampleStage.
//
// The pixel's rows two words apart: LLVM's SLP vectoriser loads adjacent rows (the
// normal's x, y, z) as 2-wide vectors and pairs the terms of its basis, which keeps the
// sample loop scalar (docs/pocl.md, rule 8): twice the time of the whole stage.
#define PIXEL_ROW_STRIDE 2
#define CHUNK_SAMPLES (MA_PASSES_PER_CHUNK * MA_PIXEL_LANES)

// Adds terms [0, count) of a chunk of technique k's samples (one-sample: each term's own).
MA_FN void addChunk(__local PixelSums* pixelSums, __local const float* terms, int count, int k) {
  PixelSums sums = *pixelSums;
  for (int t = 0; t < count; ++t) {
    SampleContribution s;
    s.r = terms[TERM_R * CHUNK_SAMPLES + t];
    s.g = terms[TERM_G * CHUNK_SAMPLES + t];
    s.b = terms[TERM_B * CHUNK_SAMPLES + t];
    s.w = terms[TERM_W * CHUNK_SAMPLES + t];
    s.technique = MA_ONE_SAMPLE ? as_int(terms[TERM_TECHNIQUE * CHUNK_SAMPLES + t]) : k;
    addContribution(&sums, s);
  }
  *pixelSums = sums;
}

// Each pixel's rows in a block of ROW_BLOCK words, a power of two: its row r at
// (q·ROW_BLOCK) xor r, which is q·ROW_BLOCK + r, and leaves LLVM no 64-bit q (rule 10).
#define ROW_BLOCK MA_ROW_BLOCK(ROW_COUNT)
// pixelRows: the inputs of the pixel being sampled (its rows before the CDFs'), then
// its index and its block's first word.
enum { ROW_SAMPLED_PIXEL = ROW_PIXEL_CDF, ROW_SAMPLED_BLOCK, SAMPLED_ROWS };

// Pixel q of the work-group, to be sampled: its inputs copied to pixelRows (row r at
// r·PIXEL_ROW_STRIDE), there read at fixed addresses, and its index and the block of
// its table (its own, or its partner's: tableLane) read back from local memory. q is kept per lane across the barriers, and PoCL cannot tell
// that it is the same in every lane: rows read at q would be gathers, and what the
// sample loop computes once from the pixel's index (its Philox key, 64-bit products)
// would be kept per lane and hold the loop to 4 lanes (docs/pocl.md, rule 10). Read
// back from local memory after the barrier, each is one value for the work-group.
MA_FN void copySampledPixel(__local int* pixelRows, __local const int* groupRows, __local const int* tableLane,
                            __global const int* pixelOrder, int first, int q, int lid) {
  for (int r = lid; r < ROW_PIXEL_CDF; r += MA_PIXEL_LANES)
    pixelRows[r * PIXEL_ROW_STRIDE] = groupRows[(q * ROW_BLOCK) ^ r];
  if (lid == 0) {
    pixelRows[ROW_SAMPLED_PIXEL * PIXEL_ROW_STRIDE] = pixelOrder[first ^ q];
    pixelRows[ROW_SAMPLED_BLOCK * PIXEL_ROW_STRIDE] = tableLane[q] * ROW_BLOCK;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
}

__kernel __attribute__((reqd_work_group_size(MA_PIXEL_LANES, 1, 1))) void samplePixelStage(MA_SAMPLE_STAGE_PARAMETERS) {
  __local int groupRows[ROW_BLOCK * MA_GROUP_PIXELS];
  __local int pixelRows[SAMPLED_ROWS * PIXEL_ROW_STRIDE];
  __local float terms[TERM_COUNT * CHUNK_SAMPLES];
  __local PixelSums pixelSums;
  int lid = (int)get_local_id(0), first = (int)get_group_id(0) * MA_GROUP_PIXELS;
  int pixels = min(MA_GROUP_PIXELS, pixelCount - first);
  // Lane l loads pixel l of the work-group and builds its table as the C++ reference
  // does: the lanes build their tables side by side, each reading the cells at the same
  // addresses. A pixel whose pair's or quad's table a lane before builds (the pixels
  // that take samples, in index order: sampledPixels) samples that table instead.
  __local int tableLane[MA_GROUP_PIXELS];
  if (lid < pixels) {
    int pixel = pixelOrder[first + lid];
    loadPixelRows(groupRows, 1, lid * ROW_BLOCK, shadingPoints, counts, firstIndex, MA_COEFFICIENTS, productFloats,
                  productWords, stageSamples, pixel);
    int lane = lid;
#if MA_PIXEL_CELLS > 0
    PixelCdfInputs own = pixelCdfInputs(groupRows, 1, lid * ROW_BLOCK, stageSamples);
    TableGroup group = pixelTableGroup(own, shadingPoints, counts, firstIndex, stageSamples, pixel, imageWidth);
    // The group's pixels that take samples lie in adjacent lanes, in index order: the
    // first of them in this work-group builds.
    for (int back = 1; back < 4; ++back)
      if (lid >= back && pixelOrder[first + lid - back] >= group.first) lane = lid - back;
    PixelCdfInputs in = group.inputs;
    if (lane == lid)
      buildPixelOptimalCdf(blockProbs, MA_PIXEL_CELLS, in.brdf, in.normal, in.mirror, in.envmapShare, in.brdfCovers,
                           MA_SHARE_COLUMNS > 0, MA_PRODUCT_CELLS, groupRows + lid * ROW_BLOCK + ROW_PIXEL_CDF, 1);
#endif
    tableLane[lid] = lane;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int q = 0; q < pixels; ++q) {
    copySampledPixel(pixelRows, groupRows, tableLane, pixelOrder, first, q, lid);
    int pixel = pixelRows[ROW_SAMPLED_PIXEL * PIXEL_ROW_STRIDE];
    __local const int* cdfRows = groupRows + pixelRows[ROW_SAMPLED_BLOCK * PIXEL_ROW_STRIDE] + ROW_PIXEL_CDF;
    if (lid == 0) pixelSums = zeroPixelSums();
    int start = 0;  // the technique's first sample in the stage
    MA_UNROLL
    for (int k = 0; k < TECHNIQUE_LOOPS; ++k) {
      int n = MA_ONE_SAMPLE ? oneSamplePassSamples(pixelRows, PIXEL_ROW_STRIDE, 0)
                            : pixelRows[(ROW_N0 + k) * PIXEL_ROW_STRIDE];
      // A technique between the first and the last runs at least one pass, uncounted
      // where n is 0 (the host's LaunchWork counts it), as in sampleStage (rule 12); a
      // chunk's passes run at least once, as it holds a sample or is that pass.
      int chunk = 0;
      if (n > 0 || techniqueLeastTurns(k, TECHNIQUE_LOOPS) > 0) do {
        int passes = max(1, min(MA_PASSES_PER_CHUNK, (n - chunk + MA_PIXEL_LANES - 1) / MA_PIXEL_LANES));
        int p = 0;
        do {
          // (pL) xor l is pL + l: written so, LLVM cannot make it a 64-bit induction variable.
          int t = (p * MA_PIXEL_LANES) ^ lid, jk = chunk + t;
          SampleContribution c = sampleOfPixel(texels, cdfTable, aliasTable, blockProbs, productFloats, productWords,
                                               width, height, coskExponent, blockLog2, pixelRows, PIXEL_ROW_STRIDE, 0,
                                               cdfRows, 1, stageSamples, seedLo, seedHi, firstPixel, pixel, k, jk);
          terms[TERM_R * CHUNK_SAMPLES + t] = c.r;
          terms[TERM_G * CHUNK_SAMPLES + t] = c.g;
          terms[TERM_B * CHUNK_SAMPLES + t] = c.b;
          terms[TERM_W * CHUNK_SAMPLES + t] = c.w;
          if (MA_ONE_SAMPLE) terms[TERM_TECHNIQUE * CHUNK_SAMPLES + t] = as_float(c.technique);
          if (MA_STORE_SAMPLES)
            storeSample(samples, c, jk < n, pixel, firstSlot + start + jk, sampleCapacity, spareSamples, lid);
          barrier(CLK_LOCAL_MEM_FENCE);  // keeps PoCL's work-item loop innermost: vectorised across samples
          ++p;
        } while (p < passes);
        if (lid == 0) addChunk(&pixelSums, terms, min(CHUNK_SAMPLES, n - chunk), k);
        barrier(CLK_LOCAL_MEM_FENCE);
        chunk += CHUNK_SAMPLES;
      } while (chunk < n);
      start += n;
    }
    if (lid == 0) {
      __global ma_acc* e = estimate + estimateOffset(pixel);
      e[0] = pixelSums.r;
      e[1] = pixelSums.g;
      e[2] = pixelSums.b;
      __global ma_acc* m = moments + momentsOffset(pixel, MA_TECHNIQUES);
      m[0] = pixelSums.w0;
      m[1] = pixelSums.ww0;
      m[2] = pixelSums.w1;
      m[3] = pixelSums.ww1;
      if (MA_TECHNIQUES > 2) {
        m[4] = pixelSums.w2;
        m[5] = pixelSums.ww2;
      }
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
}
#endif
