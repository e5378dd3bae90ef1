#pragma once
// The envmap's sampling distribution, laid out as kernels/envmap.h reads it: texel
// probabilities ∝ luminance × sin θ (or its MIS-compensated form, [Kar19] eq. 14, ×
// sin θ), and either an alias table or marginal and conditional CDFs that draw texels
// with those probabilities; or, for the optimal pdf ([Kar19] eq. 9), a bank of such
// tables over blocks of texels (host/distributions/OptimalBank.h).
#include <array>
#include <cstdint>
#include <vector>

#include "KernelCode.h"
#include "distributions/AliasTable.h"
#include "distributions/CompensatedPdf.h"
#include "distributions/OptimalBank.h"
#include "scene/BrdfGrid.h"
#include "scene/Envmap.h"

namespace misalloc {

enum class EnvmapSampler { Alias, Cdf };

// The buffers behind kernels/envmap.h's EnvmapView (never empty: OpenCL buffers can't be).
struct EnvmapTables {
  int width = 0, height = 0;
  // 4 per texel: R, G, B, and the probability that the sampler draws the texel.
  std::vector<float> texels;
  // CDF sampler: the marginal CDF over rows (H + 1 values, [0] = 0, [H] = 1), then for
  // each row its conditional CDF over columns (W + 1 values, [0] = 0, [W] = 1).
  // Alias sampler: one unused 0.
  std::vector<float> cdfTable;
  // Alias sampler: per bucket, the bits of its float acceptance probability and its
  // alias, side by side so that one cache line serves a draw. CDF sampler: one unused 0.
  std::vector<uint32_t> aliasTable;
  bool useCdf = false;
  int cdfStepsRow = 0, cdfStepsCol = 0;  // ceil(log2(H)), ceil(log2(W)): searchCdf's steps
  // The map is black, so the texels are drawn ∝ sin θ instead: uniform over the
  // sphere. The radiance stays 0; callers should say so.
  bool uniformFallback = false;
  // The pdf asked for, and the one the tables hold: a compensated pdf that leaves no
  // texel positive (a constant map with C ≤ 0.5) falls back to plain; callers should
  // say so. Plain also on uniformFallback.
  EnvmapPdf requestedPdf, pdf;
  double meanLuminance = 0;      // L̄ of [Kar19] eq. 14 (solidAngleMeanLuminance)
  double zeroTexelFraction = 0;  // compensated: the texels it never draws (L ≤ 2(1−C)·L̄)

  // The optimal pdf's bank, laid out as kernels/envmap.h's EnvmapView describes; none
  // while bankShares = 0. Then texels[4t + 3] is t's probability within its block.
  int bankShares = 0, blockLog2 = 0;
  int brdfBins = 0;
  std::vector<float> blockProbs{0};  // per entry, per block (never empty: an OpenCL buffer)
  std::vector<int> brdfBinOfPixel;   // the kernels read it as the 4th float of the pixel's BRDF
  BankVariances bankVariances;
  double bankBuildSeconds = 0;  // building every table from the map's luminance, or reading them (bankFromCache)
  bool bankFromCache = false;   // read from the bank cache (BankCache.h)

  // The optimal pdf per pixel (kernels/pixel_optimal.h): > 0, the cells, blocks of
  // 2^blockLog2 texels a side, laid out as the bank's; blockProbs then holds each
  // cell's MA_CELL_FLOATS, and texels[4t + 3] is t's probability within its cell.
  int pixelCells = 0;
  int pixelCdfSteps = 0;  // ceil(log2(pixelCells)): searchPixelCdf's steps

  bool hasBank() const { return bankShares > 0; }
  // The envmap technique's pdf depends on the stage's envmap share (bankEntryOf,
  // buildPixelOptimalCdf): a stage of another α samples from another table.
  bool followsEnvmapShare() const { return bankShares > 0 || pixelCells > 0; }
  // The shares whose tables a stored sample's share columns may hold (kernels/stats.h):
  // the bank's, or the three the optimal pdf per pixel evaluates (pixelSharePdfs).
  int shareColumns() const { return bankShares > 0 ? bankShares : (pixelCells > 0 ? MA_MAX_BANK_SHARES : 0); }
};

// Texel weights are the luminance 0.2126 R + 0.7152 G + 0.0722 B (compensated with
// `pdf`) times sin θ at the texel's centre, so that the solid-angle pdf is ∝ luminance
// (compensated). Probabilities and prefix sums are computed in double and stored as float; a texel of weight 0 is never
// drawn by either sampler. The alias sampler stores the weights' probabilities. The
// CDF sampler stores the probabilities its float CDFs realise with the kernel's 24-bit
// uniforms: they differ from the weights' by up to ~2^-24 (W+H) in total, and an
// estimate that divides by the stored pdf stays exactly unbiased. The texels must be finite and ≥ 0, as readExr and
// makeEnvmap make them (else std::invalid_argument). Throws InputError, naming the
// map, if it has too many texels for the kernels' 32-bit int indexing.
EnvmapTables buildEnvmapTables(const Envmap& envmap, EnvmapSampler sampler, const EnvmapPdf& pdf = {});

// The texels' luminance × sin θ, the plain pdf's weights; sin θ alone for a black map.
// The texels must be finite and ≥ 0 (else std::invalid_argument).
std::vector<double> plainTexelWeights(const RgbImage& image);

// An alias table's acceptance probability and alias of each bucket, interleaved, as
// kernels/envmap.h's sampleAliasTable reads them.
std::vector<uint32_t> interleave(const AliasTable& alias);

// Each block's alias table over its 2^L × 2^L slots (row-major in the block), ∝ the
// texels' weights, at table[2 · (block · 4^L + slot)]; slots past the map's edge weigh
// 0. A block of no weight is never drawn; its table is uniform over its texels so that
// it stays valid. kernels/envmap.h's sampleTexelInBlock reads it.
void writeBlockSlotTables(const std::vector<double>& weights, int width, int height, int blockLog2, uint32_t* table);

// The optimal pdf for the grid's BRDFs seen from `mirror`: the bank of block tables
// (alias or CDF, as `sampler`), each block's texels drawn by alias tables ∝ luminance ×
// sin θ. A black map falls back to plain (uniform) tables.
EnvmapTables buildOptimalEnvmapTables(const Envmap& envmap, EnvmapSampler sampler, const BrdfGrid& grid,
                                      const std::array<float, 3>& mirror, const OptimalBankOptions& options = {});

// log2 of the optimal pdf per pixel's cells' side in texels for a map of width × height
// texels: at least 1, with at most `cellsAcross` cells across (EnvmapPdf::cellsAcross)
// and MA_MAX_PIXEL_CELLS in all.
int pixelCellLog2(int width, int height, int cellsAcross);
constexpr int kMaxPixelCellLog2 = 12;

// The optimal pdf per pixel's tables: cells of 2^pixelCellLog2 texels a side with their
// centres, plain masses and solid angles; each cell's texels drawn by an alias table ∝
// luminance × sin θ. A black map falls back to plain (uniform) tables.
EnvmapTables buildPixelOptimalEnvmapTables(const Envmap& envmap, int cellsAcross = kDefaultPixelCellsAcross);

}  // namespace misalloc
