// Where a pixel's values lie, defined once: in the sampling kernels' per-pixel buffers
// and in the rows of local memory that kernels/sample.cl reads them into. The host sizes
// its buffers and local memory and reads its results by the same definitions
// (host/sampling/Sampler.cpp, host/sampling/HostSampler.cpp, host/cl/LaunchShape.cpp).
#include "namespace_check.h"
#ifndef MA_PIXEL_LAYOUT_H
#define MA_PIXEL_LAYOUT_H
#include "common.h"

// sampleStage's sums, one row of local memory per sum: R, G, B, then per technique Σ w
// and Σ w².
enum { SUM_R, SUM_G, SUM_B, SUM_W0, SUM_W1, SUM_W2, SUM_WW0, SUM_WW1, SUM_WW2, SUM_COUNT };

// What a pixel's samples share, one 32-bit word per row: its shading point (BRDF, BRDF
// bin, normal, mirror direction), counts and first sample indices; then, with --weights
// optimal, the coefficients a_{c,k} at row ROW_COEFFICIENTS + c·M + k; then, with
// --product's tables, its ProductMixture (diffuse, specular, specular table); then, with the
// optimal pdf per pixel, its CDF over the cells and the build's scratch
// (kernels/pixel_optimal.h, MA_PIXEL_CDF_ROWS).
enum {
  ROW_RHO_D,
  ROW_RHO_S,
  ROW_N,
  ROW_BRDF_BIN,
  ROW_NORMAL_X,
  ROW_NORMAL_Y,
  ROW_NORMAL_Z,
  ROW_MIRROR_X,
  ROW_MIRROR_Y,
  ROW_MIRROR_Z,
  ROW_N0,
  ROW_N1,
  ROW_N2,
  ROW_FIRST0,
  ROW_FIRST1,
  ROW_FIRST2,
  ROW_COEFFICIENTS
};
// Macros, for the kernel's local arrays; pixelRowCount for the host.
#define MA_ROW_PRODUCT(optimalWeights, techniqueCount) \
  (ROW_COEFFICIENTS + ((optimalWeights) ? 3 * (techniqueCount) : 0))
#define MA_ROW_PIXEL_CDF(optimalWeights, techniqueCount, product) \
  (MA_ROW_PRODUCT(optimalWeights, techniqueCount) + ((product) ? 3 : 0))
// The optimal pdf per pixel's rows: its CDF's pixelCells + 1 entries, then the build's
// scratch, 2 pixelCells entries and 4 per chunk (kernels/pixel_optimal.h, CHUNK_SUMS),
// then with the product technique from the same cells (productCells) its CDF's
// pixelCells + 1 entries, then with the share columns (shareColumns) each share's
// table's mass in each cell, 3 pixelCells entries for at most 3 shares
// (MA_MAX_BANK_SHARES; kernels/pixel_optimal.h, MA_SHARE_MASS_ROW), after the product's
// rows, which are kept for them whether the product technique runs or not.
#define MA_PIXEL_CHUNKS 16
#define MA_PIXEL_SHARE_MASS_ROWS(pixelCells) (3 * (pixelCells))
#define MA_PIXEL_CDF_ROWS(pixelCells, productCells, shareColumns)                                                 \
  ((pixelCells) > 0                                                                                               \
       ? 3 * (pixelCells) + 1 + 4 * MA_PIXEL_CHUNKS + ((productCells) || (shareColumns) ? (pixelCells) + 1 : 0) + \
             ((shareColumns) ? MA_PIXEL_SHARE_MASS_ROWS(pixelCells) : 0)                                          \
       : 0)
#define MA_PIXEL_ROW_COUNT(optimalWeights, techniqueCount, product, pixelCells, productCells, shareColumns) \
  (MA_ROW_PIXEL_CDF(optimalWeights, techniqueCount, product) +                                              \
   MA_PIXEL_CDF_ROWS(pixelCells, productCells, shareColumns))

// product: the product technique's mixture rows (its tables, kernels/product.h);
// productCells: its CDF over the optimal pdf's cells; shareColumns: the stored samples'
// share columns (kernels/stats.h), whose pdfs the cells' masses give.
MA_FN int pixelRowCount(int optimalWeights, int techniqueCount, int product, int pixelCells, int productCells,
                        int shareColumns) {
  return MA_PIXEL_ROW_COUNT(optimalWeights, techniqueCount, product, pixelCells, productCells, shareColumns);
}

// The turns that the loop over technique k's samples, of `loops` such loops in a stage
// (kernels/sample.cl), runs at the least, its count 0 or not: 1 between the first
// technique and the last, else 0. A loop around a barrier that may run no turn makes
// PoCL copy each later technique's loops (docs/pocl.md, rule 12); the host's LaunchWork
// counts the turn.
MA_FN int techniqueLeastTurns(int k, int loops) { return k > 0 && k + 1 < loops ? 1 : 0; }

// samplePixelStage's chunk of sample terms (kernels/sample.cl): per term, a float for
// each of MA_PASSES_PER_CHUNK passes of its lanes.
#define MA_PASSES_PER_CHUNK 8
enum { TERM_R, TERM_G, TERM_B, TERM_W, TERM_TECHNIQUE, TERM_COUNT };

// The words of a pixel's block of rows in samplePixelStage (kernels/sample.cl): the
// least power of two that holds its `rows` rows, up to 2^20.
#define MA_ROW_BLOCK(rows)     \
  ((rows) <= 256      ? 256    \
   : (rows) <= 512    ? 512    \
   : (rows) <= 1024   ? 1024   \
   : (rows) <= 2048   ? 2048   \
   : (rows) <= 4096   ? 4096   \
   : (rows) <= 8192   ? 8192   \
   : (rows) <= 16384  ? 16384  \
   : (rows) <= 32768  ? 32768  \
   : (rows) <= 65536  ? 65536  \
   : (rows) <= 131072 ? 131072 \
   : (rows) <= 262144 ? 262144 \
   : (rows) <= 524288 ? 524288 \
                      : 1048576)
MA_FN int pixelRowBlock(int rows) { return MA_ROW_BLOCK(rows); }

// The order of the pixel's CDF over its cells: chunk by chunk, chunk j holding cells j,
// j + K, j + 2K, ... (K = MA_PIXEL_CHUNKS). The build adds each chunk's masses and
// writes each chunk's entries on its own (kernels/pixel_optimal.h): the K sums of cells
// side by side lie side by side, and a compiler vectorises across them.
MA_FN int chunkOfCell(int c) { return c % MA_PIXEL_CHUNKS; }
MA_FN int chunkLength(int count, int j) { return count / MA_PIXEL_CHUNKS + (j < count % MA_PIXEL_CHUNKS ? 1 : 0); }
// The CDF position of chunk j's first cell.
MA_FN int chunkStart(int count, int j) {
  int shorter = count / MA_PIXEL_CHUNKS, longer = count % MA_PIXEL_CHUNKS;
  return j * shorter + (j < longer ? j : longer);
}
MA_FN int cdfPositionOfCell(int count, int c) { return chunkStart(count, chunkOfCell(c)) + c / MA_PIXEL_CHUNKS; }
MA_FN int cellAtCdfPosition(int count, int p) {
  int shorter = count / MA_PIXEL_CHUNKS, longer = count % MA_PIXEL_CHUNKS, inLonger = longer * (shorter + 1);
  int j = p < inLonger ? p / (shorter + 1) : longer + (shorter > 0 ? (p - inLonger) / shorter : 0);
  return (p - chunkStart(count, j)) * MA_PIXEL_CHUNKS + j;
}

// The per-pixel buffers, pixel p's first element. Shading point words: the first
// ROW_N0 rows, ρ_d to the mirror direction's z.
#define MA_SHADING_POINT_WORDS ROW_N0
MA_FN int shadingPointOffset(int pixel) { return MA_SHADING_POINT_WORDS * pixel; }
// The estimate: R, G, B.
MA_FN int estimateOffset(int pixel) { return 3 * pixel; }
// The moments: Σ w, Σ w² per technique.
MA_FN int momentsOffset(int pixel, int techniqueCount) { return 2 * techniqueCount * pixel; }
// The optimal weights' coefficients: a_{c,k} at c·M + k.
MA_FN int coefficientsOffset(int pixel, int techniqueCount) { return 3 * techniqueCount * pixel; }
// The running sums: `slots` per pixel (MA_STATS_PER_TECHNIQUE per technique, kernels/stats.h).
MA_FN int statsOffset(int pixel, int slots) { return slots * pixel; }
// The counts and first sample indices: technique k's at k.
MA_FN int countsOffset(int pixel, int techniqueCount) { return techniqueCount * pixel; }

#endif
