#pragma once
// A lat-long map cut into blocks of 2^L × 2^L texels, and each block into cells of up to
// 4 × 4 texels at whose centres a lobe is evaluated: the optimal pdf's bank and the
// product technique integrate L × BRDF × cos over a block so, which keeps their builds a
// few percent of a render while the texels keep their full resolution.
#include <cstddef>
#include <vector>

#include "KernelCode.h"

namespace misalloc {

struct BlockCell {
  kern::MaVec3 direction;            // the cell's centre
  double plain = 0, solidAngle = 0;  // Σ of its texels' plain weights, Σ of their sin θ
  std::size_t block = 0;             // the block that holds it
};

struct BlockCells {
  int across = 0, down = 0;  // blocks
  std::vector<BlockCell> cells;
  std::vector<double> plainBlockMass;  // Σ of the plain weights over each block
};

// `plainWeights`: the texels' luminance × sin θ, row-major.
BlockCells blockCells(const std::vector<double>& plainWeights, int width, int height, int blockLog2);

}  // namespace misalloc
