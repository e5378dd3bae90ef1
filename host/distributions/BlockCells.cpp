#include "distributions/BlockCells.h"

#include <algorithm>
#include <cmath>

#include "Constants.h"

namespace misalloc {

BlockCells blockCells(const std::vector<double>& plainWeights, int width, int height, int blockLog2) {
  const int side = 1 << blockLog2;
  BlockCells out;
  out.across = (width + side - 1) / side;
  out.down = (height + side - 1) / side;
  // 16 evaluations per 8 × 8 block.
  const int cellLog2 = std::min(blockLog2, 2), cellSide = 1 << cellLog2;
  const int cellsAcross = (width + cellSide - 1) / cellSide, cellsDown = (height + cellSide - 1) / cellSide;
  out.cells.resize(std::size_t(cellsAcross) * cellsDown);
  out.plainBlockMass.assign(std::size_t(out.across) * out.down, 0.0);
  for (int row = 0; row < height; ++row) {
    const double sinTheta = std::sin(kPi * (row + 0.5) / height);
    BlockCell* cellRow = out.cells.data() + std::size_t(row >> cellLog2) * cellsAcross;
    double* massRow = out.plainBlockMass.data() + std::size_t(row >> blockLog2) * out.across;
    const double* weightRow = plainWeights.data() + std::size_t(row) * width;
    for (int col = 0; col < width; ++col) {
      cellRow[col >> cellLog2].plain += weightRow[col];
      cellRow[col >> cellLog2].solidAngle += sinTheta;
      massRow[col >> blockLog2] += weightRow[col];
    }
  }
  for (int cellRow = 0; cellRow < cellsDown; ++cellRow)
    for (int cellCol = 0; cellCol < cellsAcross; ++cellCol) {
      BlockCell& cell = out.cells[std::size_t(cellRow) * cellsAcross + cellCol];
      const double rows = std::min(cellSide, height - cellRow * cellSide);
      const double cols = std::min(cellSide, width - cellCol * cellSide);
      const double theta = kPi * (cellRow * cellSide + 0.5 * rows) / height;
      const double phi = 2 * kPi * (cellCol * cellSide + 0.5 * cols) / width;
      cell.direction = kern::makeVec3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
                                      float(std::cos(theta)));
      cell.block = std::size_t(cellRow * cellSide / side) * out.across + cellCol * cellSide / side;
    }
  return out;
}

}  // namespace misalloc
