#pragma once
// The product technique's tables ([CL18]), laid out as kernels/product.h's ProductView
// reads them: over blocks of the map, the plain envmap's table, the diffuse product
// L cos and one specular product L cos^n α cos per exponent bin that the grid's pixels
// fall in; within each block, the texels by luminance × sin θ. A pixel's product mixes
// them with its own BRDF's weights (productMixture), so no table is per pixel. With the
// optimal pdf per pixel the product is the pixel's own table over its cells
// (kernels/pixel_optimal.h), and there are no tables (pixelCells).
#include <array>
#include <cstdint>
#include <vector>

#include "scene/BrdfGrid.h"
#include "scene/Envmap.h"

namespace misalloc {

struct ProductTables {
  int tables = 0;  // 0: no product technique
  int blockLog2 = 0;
  // Never empty: OpenCL buffers can't be.
  std::vector<float> floats{0};
  std::vector<uint32_t> words{0, 0};
  // The envmap technique's texel probabilities are the plain ones the product reads
  // (the plain pdf, no bank, the alias sampler's stored weights): kernels/product.h
  // then scales the envmap's pdf instead of reading its own. Set by makeScene.
  bool plainTexels = false;
  // The product from the optimal pdf per pixel's cells: no tables. Set by makeScene.
  bool pixelCells = false;
  double buildSeconds = 0;

  bool enabled() const { return tables > 0 || pixelCells; }
  std::size_t bytes() const { return floats.size() * sizeof(float) + words.size() * sizeof(uint32_t); }
};

// 8 × 8-texel blocks, the optimal pdf's bank's (OptimalBankOptions): at 1024 × 512
// texels, 8192 blocks of 12 bytes per table.
constexpr int kProductBlockLog2 = 3;

// The tables for the grid's BRDFs seen from `mirror`. The texels must be finite and
// ≥ 0 (readExr and makeEnvmap make them so).
ProductTables buildProductTables(const Envmap& envmap, const BrdfGrid& grid, const std::array<float, 3>& mirror,
                                 int blockLog2 = kProductBlockLog2);

}  // namespace misalloc
