#pragma once
// The optimal envmap pdf of [Kar19] eq. 9 for every pixel, tabulated. Every pixel has
// the same normal and view, so its integrand L ρ cos differs from another's only by
// the BRDF, and eq. 9 also depends on the envmap technique's share C: the bank holds
// one table per (BRDF bin, C). A table is coarse, over blocks of 2^L × 2^L texels, and
// the plain pdf picks the texel within the block, so that a table costs a few
// milliseconds to build and kilobytes to hold while a small sun keeps its full
// resolution. kernels/envmap.h samples it (sampleEnvmapBank, bankEntryOf).
#include <array>
#include <vector>

#include "scene/BrdfGrid.h"

namespace misalloc {

struct OptimalBankOptions {
  int exponentBins = 8;  // log-spaced over the grid's Phong exponents
  int diffuseBins = 2;   // over its diffuse lobe weights ρd/(ρd+ρs)
  int shares = 3;        // C_i = (i+1)/(shares+1): 1/4, 1/2, 3/4
  int blockLog2 = 3;     // 8 × 8-texel blocks
};

// The grid's BRDFs binned by exponent (log) and diffuse lobe weight, each pixel in the
// nearest bin; a bin's BRDF is its centre, with ρd + ρs = 1 (eq. 9 is blind to scale).
// A dimension the grid does not vary gets one bin.
struct BrdfBins {
  std::vector<PhongParameters> centres;
  std::vector<int> binOfPixel;
};
BrdfBins binBrdfs(const BrdfGrid& grid, int exponentBins, int diffuseBins);

// C of share i, the inverse of kernels/envmap.h's bankEntryOf.
double bankShare(int i, int shares);

// What eq. 9 buys, from the block tables themselves: the one-sample estimator's
// variance ([Kar19] eq. 7 less F²) of each entry's pdf, on its blocks.
struct BankVariances {
  double compensatedOverOptimalMax = 1;  // eq. 6 against eq. 9: 1 where eq. 5 is never negative
  double compensatedOverOptimalMean = 1;
  int entriesWithNegativeEq5 = 0;
};

// Per entry (bin × shares + i), each block's weight: [Kar19] eq. 9 with f and
// q = (1−C) p_ρ integrated over the block (at the centres of 4 × 4-texel cells), λ by bisection
// within eq. 10. `plainWeights` are the texels' luminance × sin θ. An entry whose BRDF
// sees no light keeps the plain block weights.
struct OptimalBankWeights {
  std::vector<std::vector<double>> entries;
  std::vector<double> plainBlockMass;  // Σ of plainWeights over each block
  BankVariances variances;
};
OptimalBankWeights optimalBlockWeights(const std::vector<double>& plainWeights, int width, int height,
                                       const BrdfBins& bins, const std::array<float, 3>& mirror,
                                       const OptimalBankOptions& options);

}  // namespace misalloc
