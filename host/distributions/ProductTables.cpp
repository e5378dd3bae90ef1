#include "distributions/ProductTables.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "KernelCode.h"
#include "distributions/BlockCells.h"
#include "distributions/EnvmapDistribution.h"

namespace misalloc {
namespace {

// The geometric centre of exponent bin i (kern::productExponentBin): n + 1 in
// [2^e (1 + m/2), 2^e (1 + (m+1)/2)), e = i/2, m = i mod 2.
float binExponent(int bin) {
  const double lo = std::ldexp(1.0 + 0.5 * (bin % 2), bin / 2), hi = std::ldexp(1.0 + 0.5 * (bin % 2 + 1), bin / 2);
  return float(std::sqrt(lo * hi) - 1);
}

// Each exponent bin's table and each table's exponent: the bins the grid's pixels fall
// in get a specular table each, 2, 3, ... in the bins' order; a bin no pixel falls in
// takes the nearest one's, so that any exponent finds a table.
struct ExponentTables {
  std::vector<int> tableOfBin;
  std::vector<float> exponentOfTable;  // indexed by table; 0 for the plain and diffuse ones
};

ExponentTables exponentTables(const BrdfGrid& grid) {
  std::vector<char> used(MA_PRODUCT_EXPONENT_BINS, 0);
  for (const PhongParameters& p : grid.pixels) used[kern::productExponentBin(p.n)] = 1;
  std::vector<int> present;
  ExponentTables e;
  e.exponentOfTable.assign(MA_PRODUCT_TABLE_DIFFUSE + 1, 0.0f);
  for (int bin = 0; bin < MA_PRODUCT_EXPONENT_BINS; ++bin)
    if (used[bin]) present.push_back(bin), e.exponentOfTable.push_back(binExponent(bin));
  for (int bin = 0; bin < MA_PRODUCT_EXPONENT_BINS; ++bin) {
    std::size_t nearest = 0;
    for (std::size_t j = 1; j < present.size(); ++j)
      if (std::abs(present[j] - bin) < std::abs(present[nearest] - bin)) nearest = j;
    e.tableOfBin.push_back(MA_PRODUCT_TABLE_DIFFUSE + 1 + int(nearest));
  }
  return e;
}

}  // namespace

ProductTables buildProductTables(const Envmap& envmap, const BrdfGrid& grid, const std::array<float, 3>& mirror,
                                 int blockLog2) {
  const auto start = std::chrono::steady_clock::now();
  const RgbImage& image = envmap.image;
  const std::vector<double> weights = plainTexelWeights(image);
  const BlockCells cells = blockCells(weights, image.width, image.height, blockLog2);
  const std::size_t blocks = cells.plainBlockMass.size(), slots = std::size_t(1) << (2 * blockLog2);
  const ExponentTables exponents = exponentTables(grid);

  ProductTables t;
  t.tables = int(exponents.exponentOfTable.size());
  t.blockLog2 = blockLog2;
  // Each table's block weights: the plain mass, then L cos and L cos^n α cos at the cells.
  std::vector<std::vector<double>> tableWeights(t.tables, std::vector<double>(blocks, 0.0));
  tableWeights[MA_PRODUCT_TABLE_PLAIN] = cells.plainBlockMass;
  const kern::MaVec3 r = kern::makeVec3(mirror[0], mirror[1], mirror[2]);
#pragma omp parallel for schedule(dynamic, 1)
  for (int table = MA_PRODUCT_TABLE_DIFFUSE; table < t.tables; ++table) {
    kern::PhongParams lobe;
    lobe.rhoD = lobe.rhoS = 0;
    lobe.n = exponents.exponentOfTable[table];
    std::vector<double>& w = tableWeights[table];
    for (const BlockCell& cell : cells.cells) {
      const double cosTheta = std::max(cell.direction.z, 0.0f);
      const double shape = table == MA_PRODUCT_TABLE_DIFFUSE ? 1.0 : kern::phongLobe(lobe, cell.direction, r);
      w[cell.block] += cell.plain * shape * cosTheta;
    }
  }

  const std::size_t binWords = MA_PRODUCT_EXPONENT_BINS, texels = weights.size();
  t.floats.assign(t.tables + t.tables * blocks + texels, 0.0f);
  t.words.assign(binWords + 2 * t.tables * blocks + 2 * blocks * slots, 0u);
  for (int bin = 0; bin < MA_PRODUCT_EXPONENT_BINS; ++bin) t.words[bin] = uint32_t(exponents.tableOfBin[bin]);
  const double plainTotal = std::accumulate(weights.begin(), weights.end(), 0.0);
  for (int table = 0; table < t.tables; ++table) {
    std::vector<double> w = tableWeights[table];
    double total = std::accumulate(w.begin(), w.end(), 0.0);
    t.floats[table] = float(total);
    // A lobe that sees no light has weight 0 in every mixture (productMixture): its
    // table only has to stay valid. The plain mass is positive (plainTexelWeights).
    if (!(total > 0)) {
      w = cells.plainBlockMass;
      total = std::accumulate(w.begin(), w.end(), 0.0);
    }
    float* ratios = t.floats.data() + t.tables + table * blocks;
    for (std::size_t b = 0; b < blocks; ++b) {
      const double plain = cells.plainBlockMass[b] / plainTotal;
      ratios[b] = float(plain > 0 ? (w[b] / total) / plain : 0.0);
    }
    const std::vector<uint32_t> alias = interleave(buildAliasTable(std::move(w)));
    std::copy(alias.begin(), alias.end(), t.words.begin() + std::ptrdiff_t(binWords + 2 * table * blocks));
  }
  // Each texel's plain probability, as buildEnvmapTables stores it for the plain pdf.
  float* plain = t.floats.data() + t.tables + t.tables * blocks;
  for (std::size_t i = 0; i < texels; ++i) plain[i] = float(weights[i] / plainTotal);
  writeBlockSlotTables(weights, image.width, image.height, blockLog2,
                       t.words.data() + binWords + 2 * t.tables * blocks);
  t.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return t;
}

}  // namespace misalloc
