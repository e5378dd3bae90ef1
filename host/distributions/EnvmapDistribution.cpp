#include "distributions/EnvmapDistribution.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "Constants.h"
#include "Error.h"
#include "KernelCode.h"
#include "distributions/AliasTable.h"

namespace misalloc {
namespace {

double sinThetaOfRow(int row, int height) { return std::sin(kPi * (row + 0.5) / height); }

// A texel's solid angle in a row of a W × H lat-long map: sin θ dφ dθ.
double texelSolidAngle(int row, int width, int height) {
  return sinThetaOfRow(row, height) * ((2 * kPi / width) * (kPi / height));
}

// The cell of 2^log2 × 2^log2 texels, `across` of them a row, that holds texel (row, col).
std::size_t cellOfTexel(int row, int col, int log2, int across) {
  return std::size_t(row >> log2) * std::size_t(across) + std::size_t(col >> log2);
}

void requireValidSize(const Envmap& envmap) {
  const RgbImage& image = envmap.image;
  // kernels/envmap.h indexes the texels' floats as int 4·t.
  if (int64_t(image.width) * image.height * 4 > INT_MAX)
    throw InputError(fmt::format("envmap '{}' has {}×{} texels, too many for the kernels' 32-bit indices (at most {})",
                                 envmap.description, image.width, image.height, INT_MAX / 4));
  // kernels/envmap.h's rowOfIndex divides texel and block indices by the width in float.
  if (image.width >= (1 << 22) || image.height >= (1 << 22))
    throw InputError(fmt::format("envmap '{}' has {}×{} texels: the kernels take at most {} a side", envmap.description,
                                 image.width, image.height, (1 << 22) - 1));
  if (image.width < 1 || image.height < 1 ||
      image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3)
    throw std::invalid_argument(fmt::format("envmap '{}' has {}×{} texels and {} floats", envmap.description,
                                            image.width, image.height, image.rgb.size()));
}

// 0.2126 R + 0.7152 G + 0.0722 B per texel.
std::vector<double> texelLuminance(const RgbImage& image) {
  std::vector<double> luminance(std::size_t(image.width) * std::size_t(image.height));
  for (std::size_t t = 0; t < luminance.size(); ++t) {
    double r = image.rgb[3 * t], g = image.rgb[3 * t + 1], b = image.rgb[3 * t + 2];
    if (!(r >= 0 && g >= 0 && b >= 0) || !std::isfinite(r + g + b))
      throw std::invalid_argument(
          fmt::format("envmap texel ({}, {}) is negative or not finite", t % image.width, t / image.width));
    luminance[t] = 0.2126 * r + 0.7152 * g + 0.0722 * b;
  }
  return luminance;
}

// Luminance × sin θ at the texel centre: p(ω) = P W H / (2π² sin θ) inside a texel,
// so this makes the solid-angle pdf ∝ luminance up to the variation of sin θ across it.
std::vector<double> sinThetaWeighted(std::vector<double> luminance, int width, int height) {
  for (int row = 0; row < height; ++row) {
    double sinTheta = sinThetaOfRow(row, height);
    for (int col = 0; col < width; ++col) luminance[std::size_t(row) * std::size_t(width) + col] *= sinTheta;
  }
  return luminance;
}

// What the pdfs that draw a block and then a texel in it (the bank, the optimal pdf per
// pixel) build on: the texels' luminance and plain weights, and their total.
struct PlainWeights {
  std::vector<double> luminance, weights;
  double total = 0;
};

PlainWeights plainWeightsOf(const RgbImage& image) {
  PlainWeights plain;
  plain.luminance = texelLuminance(image);
  plain.weights = sinThetaWeighted(plain.luminance, image.width, image.height);
  for (double w : plain.weights) plain.total += w;
  return plain;
}

// Texels: RGB and the probability within the block of 2^L texels a side that holds them
// (0 in a block of no weight), as kernels/envmap.h's bankedProbability reads them.
std::vector<float> texelsWithinBlocks(const RgbImage& image, const std::vector<double>& weights,
                                      const std::vector<double>& blockMass, int blockLog2) {
  const int width = image.width, across = (width + (1 << blockLog2) - 1) >> blockLog2;
  std::vector<float> texels(weights.size() * 4);
#pragma omp parallel for schedule(static)
  for (int row = 0; row < image.height; ++row) {
    const double* mass = blockMass.data() + std::size_t(row >> blockLog2) * across;
    for (int col = 0; col < width; ++col) {
      const std::size_t t = std::size_t(row) * width + col;
      for (int c = 0; c < 3; ++c) texels[4 * t + c] = image.rgb[3 * t + c];
      const double blockWeight = mass[col >> blockLog2];
      texels[4 * t + 3] = float(blockWeight > 0 ? weights[t] / blockWeight : 0.0);
    }
  }
  return texels;
}

// sin θ alone: uniform over the sphere.
std::vector<double> sphereWeights(int width, int height) {
  std::vector<double> weights(std::size_t(width) * std::size_t(height));
  for (int row = 0; row < height; ++row)
    std::fill_n(weights.begin() + std::ptrdiff_t(row) * width, width, sinThetaOfRow(row, height));
  return weights;
}

// cdf[0] = 0, cdf[i] = Σ_{k<i} w_k / Σ w, cdf[n] = 1. The prefix sums run in the same
// order as the total, so after the last positive weight they equal it and the ratio
// is exactly 1: searchCdf, which picks the last i with cdf[i] ≤ u < 1, then never
// lands on a trailing zero, and a zero weight in between has cdf[i] = cdf[i+1]. A
// total of 0 (a black row, never drawn) gets a uniform CDF so the table stays valid.
void writeCdf(const double* weights, int n, float* cdf) {
  double total = 0;
  for (int i = 0; i < n; ++i) total += weights[i];
  double prefix = 0;
  cdf[0] = 0;
  for (int i = 1; i < n; ++i) {
    prefix += weights[i - 1];
    cdf[i] = float(total > 0 ? prefix / total : double(i) / n);
  }
  cdf[n] = 1;
}

// The marginal CDF over rows, then each row's conditional CDF over its columns.
std::vector<float> cdfTables(const std::vector<double>& weights, int width, int height) {
  std::vector<float> table(std::size_t(height + 1) + std::size_t(height) * std::size_t(width + 1));
  std::vector<double> rowWeights(height, 0.0);
  for (int row = 0; row < height; ++row) {
    const double* rowStart = weights.data() + std::size_t(row) * std::size_t(width);
    for (int col = 0; col < width; ++col) rowWeights[row] += rowStart[col];
    writeCdf(rowStart, width, table.data() + (height + 1) + std::size_t(row) * std::size_t(width + 1));
  }
  writeCdf(rowWeights.data(), height, table.data());
  return table;
}

// uniformFloat (kernels/rng.h) draws k / 2^24, k ∈ [0, 2^24); searchCdf picks i for
// cdf[i] ≤ u < cdf[i+1], so i is drawn for ceil(2^24 cdf[i+1]) − ceil(2^24 cdf[i]) of them.
double drawnShare(const float* cdf, int i) {
  constexpr double grid = 16777216.0;
  return (std::ceil(double(cdf[i + 1]) * grid) - std::ceil(double(cdf[i]) * grid)) / grid;
}

// The probability of each cell under the CDF sampler, exactly as drawn, at
// out[stride · cell].
void storeDrawnProbabilities(const float* cdf, int width, int height, float* out, std::size_t stride) {
  const float* marginal = cdf;
  for (int row = 0; row < height; ++row) {
    double rowShare = drawnShare(marginal, row);
    const float* conditional = marginal + (height + 1) + std::size_t(row) * std::size_t(width + 1);
    for (int col = 0; col < width; ++col)
      out[stride * (std::size_t(row) * width + col)] = float(rowShare * drawnShare(conditional, col));
  }
}

// ceil(log2(n)), 0 for n = 1: searchCdf halves its range rounding up.
int binarySearchSteps(int n) {
  int steps = 0;
  while ((int64_t(1) << steps) < n) ++steps;
  return steps;
}

// searchCdf's steps over n rows or columns (`what`), which it writes out up to
// MA_MAX_CDF_STEPS.
int cdfSearchSteps(int n, const char* what) {
  const int steps = binarySearchSteps(n);
  if (steps > MA_MAX_CDF_STEPS)
    throw InputError(fmt::format("--envmap-sampler cdf: {} {} exceed the CDF sampler's {}; use the alias sampler", n,
                                 what, int64_t(1) << MA_MAX_CDF_STEPS));
  return steps;
}

}  // namespace

std::vector<uint32_t> interleave(const AliasTable& alias) {
  std::vector<uint32_t> table(2 * alias.probability.size());
  for (std::size_t b = 0; b < alias.probability.size(); ++b) {
    std::memcpy(&table[2 * b], &alias.probability[b], sizeof(float));
    table[2 * b + 1] = alias.alias[b];
  }
  return table;
}

void writeBlockSlotTables(const std::vector<double>& weights, int width, int height, int blockLog2, uint32_t* table) {
  const int side = 1 << blockLog2, slotCount = side * side;
  const int across = (width + side - 1) / side, down = (height + side - 1) / side;
#pragma omp parallel
  {
    std::vector<double> slots(slotCount);
    std::vector<float> probability(slotCount);
    std::vector<uint32_t> alias(slotCount);
    AliasScratch scratch;
#pragma omp for schedule(static)
    for (int blockRow = 0; blockRow < down; ++blockRow)
      for (int blockCol = 0; blockCol < across; ++blockCol) {
        auto inside = [&](int s) { return blockRow * side + s / side < height && blockCol * side + s % side < width; };
        double total = 0;
        for (int s = 0; s < slotCount; ++s) {
          slots[s] =
              inside(s) ? weights[std::size_t(blockRow * side + s / side) * width + blockCol * side + s % side] : 0;
          total += slots[s];
        }
        if (!(total > 0))
          for (int s = 0; s < slotCount; ++s) slots[s] = inside(s) ? 1.0 : 0.0;
        buildAliasTable(slots.data(), slots.size(), probability.data(), alias.data(), scratch);
        uint32_t* out = table + 2 * (std::size_t(blockRow) * across + blockCol) * slotCount;
        for (int s = 0; s < slotCount; ++s) {
          std::memcpy(&out[2 * s], &probability[s], sizeof(float));
          out[2 * s + 1] = alias[s];
        }
      }
  }
}

std::vector<double> plainTexelWeights(const RgbImage& image) {
  PlainWeights plain = plainWeightsOf(image);
  return plain.total > 0 ? std::move(plain.weights) : sphereWeights(image.width, image.height);
}

EnvmapTables buildEnvmapTables(const Envmap& envmap, EnvmapSampler sampler, const EnvmapPdf& pdf) {
  requireValidSize(envmap);
  const RgbImage& image = envmap.image;
  EnvmapTables tables;
  tables.width = image.width;
  tables.height = image.height;
  tables.requestedPdf = pdf;

  const std::vector<double> luminance = texelLuminance(image);
  tables.meanLuminance = solidAngleMeanLuminance(luminance, image.width, image.height);
  std::vector<double> weights;
  if (pdf.compensated()) {
    std::vector<double> compensated(luminance.size());
    std::size_t zeros = 0;
    for (std::size_t t = 0; t < luminance.size(); ++t) {
      compensated[t] = compensatedLuminance(luminance[t], tables.meanLuminance, pdf.envmapFraction);
      zeros += compensated[t] > 0 ? 0 : 1;
    }
    if (zeros < luminance.size()) {
      weights = sinThetaWeighted(std::move(compensated), image.width, image.height);
      tables.pdf = pdf;
      tables.zeroTexelFraction = double(zeros) / double(luminance.size());
    }
  }
  if (weights.empty()) weights = sinThetaWeighted(luminance, image.width, image.height);
  double total = 0;
  for (double w : weights) total += w;
  tables.uniformFallback = !(total > 0);
  if (tables.uniformFallback) {
    weights = sphereWeights(image.width, image.height);
    total = 0;
    for (double w : weights) total += w;
  }

  tables.texels.resize(weights.size() * 4);
  for (std::size_t t = 0; t < weights.size(); ++t) {
    for (int c = 0; c < 3; ++c) tables.texels[4 * t + c] = image.rgb[3 * t + c];
    tables.texels[4 * t + 3] = float(weights[t] / total);
  }

  tables.useCdf = sampler == EnvmapSampler::Cdf;
  if (tables.useCdf) {
    tables.cdfTable = cdfTables(weights, image.width, image.height);
    tables.aliasTable = {0};
    tables.cdfStepsRow = cdfSearchSteps(image.height, "rows of texels");
    tables.cdfStepsCol = cdfSearchSteps(image.width, "columns of texels");
    storeDrawnProbabilities(tables.cdfTable.data(), image.width, image.height, tables.texels.data() + 3, 4);
  } else {
    tables.cdfTable = {0};
    tables.aliasTable = interleave(buildAliasTable(std::move(weights)));
  }
  return tables;
}

namespace {

// A pdf that draws blocks: its tables before the blocks, the map's size, the pdf and L̄;
// for a black map, the plain (uniform) tables it falls back to.
EnvmapTables blockDrawnTables(const Envmap& envmap, EnvmapSampler sampler, const PlainWeights& plain,
                              const EnvmapPdf& pdf) {
  if (!(plain.total > 0)) {
    EnvmapTables fallback = buildEnvmapTables(envmap, sampler);
    fallback.requestedPdf = pdf;
    return fallback;
  }
  EnvmapTables tables;
  tables.width = envmap.image.width;
  tables.height = envmap.image.height;
  tables.requestedPdf = tables.pdf = pdf;
  tables.meanLuminance = solidAngleMeanLuminance(plain.luminance, tables.width, tables.height);
  return tables;
}

}  // namespace

EnvmapTables buildOptimalEnvmapTables(const Envmap& envmap, EnvmapSampler sampler, const BrdfGrid& grid,
                                      const std::array<float, 3>& mirror, const OptimalBankOptions& options) {
  requireValidSize(envmap);
  const RgbImage& image = envmap.image;
  const int width = image.width, height = image.height;
  const auto start = std::chrono::steady_clock::now();
  const PlainWeights plain = plainWeightsOf(image);
  const std::vector<double>& weights = plain.weights;
  EnvmapTables tables = blockDrawnTables(envmap, sampler, plain, {EnvmapPdf::Kind::Optimal});
  if (!(plain.total > 0)) return tables;
  tables.bankShares = options.shares;
  tables.blockLog2 = options.blockLog2;
  const BrdfBins bins = binBrdfs(grid, options.exponentBins, options.diffuseBins);
  tables.brdfBins = int(bins.centres.size());
  tables.brdfBinOfPixel = bins.binOfPixel;
  OptimalBankWeights bank = optimalBlockWeights(weights, width, height, bins, mirror, options);
  tables.bankVariances = bank.variances;

  const int side = 1 << options.blockLog2;
  const int across = (width + side - 1) / side, down = (height + side - 1) / side;
  const std::vector<double>& blockMass = bank.plainBlockMass;
  tables.texels = texelsWithinBlocks(image, weights, blockMass, options.blockLog2);

  tables.useCdf = sampler == EnvmapSampler::Cdf;
  const std::size_t blocks = blockMass.size(), slotWords = 2 * blocks * side * side;
  const std::size_t cdfSize = std::size_t(down + 1) + std::size_t(down) * (across + 1);
  const std::size_t entries = bank.entries.size();
  tables.aliasTable.assign(slotWords + (tables.useCdf ? 0 : 2 * entries * blocks), 0u);
  writeBlockSlotTables(weights, width, height, options.blockLog2, tables.aliasTable.data());
  tables.blockProbs.assign(entries * blocks, 0.0f);
  if (tables.useCdf) {
    tables.cdfTable.assign(entries * cdfSize, 0.0f);
    tables.cdfStepsRow = cdfSearchSteps(down, "rows of blocks");
    tables.cdfStepsCol = cdfSearchSteps(across, "columns of blocks");
  }
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t e = 0; e < entries; ++e) {
    std::vector<double>& entry = bank.entries[e];
    float* probs = tables.blockProbs.data() + e * blocks;
    if (tables.useCdf) {
      const std::vector<float> cdf = cdfTables(entry, across, down);
      storeDrawnProbabilities(cdf.data(), across, down, probs, 1);
      std::copy(cdf.begin(), cdf.end(), tables.cdfTable.begin() + std::ptrdiff_t(e * cdfSize));
    } else {
      double entryTotal = 0;
      for (double w : entry) entryTotal += w;
      for (std::size_t k = 0; k < blocks; ++k) probs[k] = float(entry[k] / entryTotal);
      const std::vector<uint32_t> alias = interleave(buildAliasTable(std::move(entry)));
      std::copy(alias.begin(), alias.end(), tables.aliasTable.begin() + std::ptrdiff_t(slotWords + 2 * e * blocks));
    }
  }
  if (!tables.useCdf) tables.cdfTable = {0};
  tables.bankBuildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return tables;
}

int pixelCellLog2(int width, int height, int cellsAcross) {
  // At least 2 × 2 texels: sampleTexelInBlock draws a slot by a shift of 32 − 2L bits.
  // At most MA_MAX_PIXEL_CELLS cells, which searchPixelCdf's steps reach, also on a map
  // taller than the usual 2:1.
  auto cells = [&](int log2) {
    return int64_t((width + (1 << log2) - 1) >> log2) * ((height + (1 << log2) - 1) >> log2);
  };
  int log2 = 1;
  while (((width + (1 << log2) - 1) >> log2) > cellsAcross || cells(log2) > MA_MAX_PIXEL_CELLS) ++log2;
  return log2;
}

namespace {

// Per cell of 2^log2 texels a side, its frame (kernels/pixel_optimal.h, CellFrame) under
// the texels' weights `weightOf(row, col, sin θ)`: the weighed mean of their directions, and
// their variance σ² along their wider axis (the larger eigenvalue of their weighed second
// moment in the plane tangent to the mean), a texel's own extent (its θ-side²/12) added.
// A cell whose texels all weigh 0 gets no frame (variance 0).
template <typename WeightOf>
std::vector<kern::CellFrame> cellFrames(int width, int height, int log2, WeightOf weightOf) {
  const int side = 1 << log2, across = (width + side - 1) / side, down = (height + side - 1) / side;
  const std::size_t cells = std::size_t(across) * down;
  std::vector<double> sinTheta(static_cast<std::size_t>(height)), cosTheta(sinTheta.size());
  std::vector<double> sinPhi(static_cast<std::size_t>(width)), cosPhi(sinPhi.size());
  for (int row = 0; row < height; ++row) {
    sinTheta[std::size_t(row)] = sinThetaOfRow(row, height);
    cosTheta[std::size_t(row)] = std::cos(kPi * (row + 0.5) / height);
  }
  for (int col = 0; col < width; ++col) {
    sinPhi[std::size_t(col)] = std::sin(2 * kPi * (col + 0.5) / width);
    cosPhi[std::size_t(col)] = std::cos(2 * kPi * (col + 0.5) / width);
  }
  auto forEachTexel = [&](auto visit) {
    for (int row = 0; row < height; ++row)
      for (int col = 0; col < width; ++col) {
        const double st = sinTheta[std::size_t(row)];
        visit(cellOfTexel(row, col, log2, across), weightOf(row, col, st),
              st * cosPhi[std::size_t(col)], st * sinPhi[std::size_t(col)], cosTheta[std::size_t(row)]);
      }
  };
  std::vector<std::array<double, 4>> sum(cells, {0.0, 0.0, 0.0, 0.0});  // Σ w x, Σ w y, Σ w z, Σ w
  forEachTexel([&](std::size_t c, double w, double x, double y, double z) {
    sum[c][0] += w * x, sum[c][1] += w * y, sum[c][2] += w * z, sum[c][3] += w;
  });
  std::vector<kern::CellFrame> frames(cells, kern::cellFrameOf(kern::makeVec3(0.0f, 0.0f, 1.0f), 0.0f));
  std::vector<kern::MaFrame> tangents(cells);  // t and s span the plane tangent to the mean
  for (std::size_t c = 0; c < cells; ++c) {
    const double r = std::sqrt(sum[c][0] * sum[c][0] + sum[c][1] * sum[c][1] + sum[c][2] * sum[c][2]);
    if (!(sum[c][3] > 0 && r > 0)) continue;
    frames[c].centre = kern::makeVec3(float(sum[c][0] / r), float(sum[c][1] / r), float(sum[c][2] / r));
    tangents[c] = kern::frameAbout(frames[c].centre);
  }
  std::vector<std::array<double, 3>> moment(cells, {0.0, 0.0, 0.0});  // Σ w u², Σ w u v, Σ w v²
  forEachTexel([&](std::size_t c, double w, double x, double y, double z) {
    const kern::MaFrame& f = tangents[c];
    const double u = f.t.x * x + f.t.y * y + f.t.z * z, v = f.s.x * x + f.s.y * y + f.s.z * z;
    moment[c][0] += w * u * u, moment[c][1] += w * u * v, moment[c][2] += w * v * v;
  });
  const double texelExtent = (kPi / height) * (kPi / height) / 12;
  for (std::size_t c = 0; c < cells; ++c) {
    if (!(sum[c][3] > 0)) continue;
    const double uu = moment[c][0] / sum[c][3], uv = moment[c][1] / sum[c][3], vv = moment[c][2] / sum[c][3];
    const double wider = 0.5 * (uu + vv) + std::sqrt(0.25 * (uu - vv) * (uu - vv) + uv * uv);
    frames[c] = kern::cellFrameOf(frames[c].centre, float(wider + texelExtent));
  }
  return frames;
}

// A cell's peak (kernels/pixel_optimal.h, eq6Value): its texels whose light per solid
// angle is over kPeakContrast times the cell's mean, as their share of its light and of
// its solid angle. Any threshold gives a lower bound of eq. 6's integral over the cell;
// twice the mean separates a sun or a lamp from the sky around it.
struct CellPeak {
  double light = 0, area = 0;
};

constexpr double kPeakContrast = 2;

std::vector<CellPeak> cellPeaks(const std::vector<double>& weights, int width, int height, int log2,
                                const std::vector<double>& mass, const std::vector<double>& solidAngle) {
  const int across = (width + (1 << log2) - 1) >> log2;
  std::vector<CellPeak> peaks(mass.size());
  for (int row = 0; row < height; ++row) {
    const double area = texelSolidAngle(row, width, height);
    for (int col = 0; col < width; ++col) {
      const std::size_t cell = cellOfTexel(row, col, log2, across);
      const double w = weights[std::size_t(row) * width + col];
      if (w * solidAngle[cell] > kPeakContrast * mass[cell] * area) peaks[cell].light += w, peaks[cell].area += area;
    }
  }
  for (std::size_t c = 0; c < peaks.size(); ++c)
    if (mass[c] > 0) peaks[c] = {peaks[c].light / mass[c], peaks[c].area / solidAngle[c]};
  return peaks;
}

}  // namespace

EnvmapTables buildPixelOptimalEnvmapTables(const Envmap& envmap, int cellsAcross) {
  requireValidSize(envmap);
  const RgbImage& image = envmap.image;
  const int width = image.width, height = image.height;
  const auto start = std::chrono::steady_clock::now();
  const PlainWeights plain = plainWeightsOf(image);
  EnvmapTables tables =
      blockDrawnTables(envmap, EnvmapSampler::Alias, plain, {EnvmapPdf::Kind::PixelOptimal, 0.5, cellsAcross});
  if (!(plain.total > 0)) return tables;
  const int log2 = tables.blockLog2 = pixelCellLog2(width, height, cellsAcross);
  // A slot of a cell's alias table takes 2L of a draw's 32 bits, the rest are its coin.
  if (log2 > kMaxPixelCellLog2)
    throw InputError(
        fmt::format("envmap '{}' is {} texels wide: the optimal pdf per pixel with {} cells across takes at most {}",
                    envmap.description, width, cellsAcross, cellsAcross << kMaxPixelCellLog2));
  const int side = 1 << log2;
  const int across = (width + side - 1) / side, down = (height + side - 1) / side;
  tables.pixelCells = across * down;
  tables.pixelCdfSteps = binarySearchSteps(tables.pixelCells);

  // Per cell: the plain mass and the solid angle, each a sum over its texels.
  std::vector<double> mass(std::size_t(tables.pixelCells), 0.0), solidAngle(mass.size(), 0.0);
  for (int row = 0; row < height; ++row) {
    const double area = texelSolidAngle(row, width, height);
    for (int col = 0; col < width; ++col) {
      const std::size_t cell = cellOfTexel(row, col, log2, across);
      mass[cell] += plain.weights[std::size_t(row) * width + col];
      solidAngle[cell] += area;
    }
  }
  // The cell's own frame, its directions weighed by solid angle, and its light's, its
  // texels weighed as its alias table draws them (the cell's own where it holds none):
  // where the BRDF technique's mass and where f's mass lie (kernels/pixel_optimal.h).
  const std::vector<kern::CellFrame> area =
      cellFrames(width, height, log2, [](int, int, double sinTheta) { return sinTheta; });
  std::vector<kern::CellFrame> light = cellFrames(
      width, height, log2, [&](int row, int col, double) { return plain.weights[std::size_t(row) * width + col]; });
  for (std::size_t c = 0; c < light.size(); ++c)
    if (!(mass[c] > 0)) light[c] = area[c];
  const std::vector<CellPeak> peaks = cellPeaks(plain.weights, width, height, log2, mass, solidAngle);
  tables.texels = texelsWithinBlocks(image, plain.weights, mass, log2);
  tables.aliasTable.assign(2 * std::size_t(tables.pixelCells) * side * side, 0u);
  writeBlockSlotTables(plain.weights, width, height, log2, tables.aliasTable.data());
  // Cells: their frames, plain masses and solid angles (kernels/pixel_optimal.h, CELL_*).
  tables.blockProbs.assign(std::size_t(tables.pixelCells) * MA_CELL_FLOATS, 0.0f);
  for (int cell = 0; cell < tables.pixelCells; ++cell) {
    auto field = [&](int f) -> float& { return tables.blockProbs[std::size_t(f) * tables.pixelCells + cell]; };
    auto store = [&](int first, const kern::CellFrame& frame) {
      field(first) = frame.centre.x;
      field(first + 1) = frame.centre.y;
      field(first + 2) = frame.centre.z;
      field(first + 3) = frame.variance;
      field(first + 4) = frame.halfWidth;
      field(first + 5) = frame.rampScale;
    };
    store(kern::CELL_X, area[std::size_t(cell)]);
    store(kern::CELL_LIGHT_X, light[std::size_t(cell)]);
    field(kern::CELL_PLAIN) = float(mass[std::size_t(cell)] / plain.total);
    field(kern::CELL_SOLID_ANGLE) = float(solidAngle[std::size_t(cell)]);
    const CellPeak& peak = peaks[std::size_t(cell)];
    field(kern::CELL_PEAK_LIGHT) = float(peak.light);
    field(kern::CELL_PEAK_GAP) = float(peak.light - peak.area);
  }
  tables.cdfTable = {0};
  tables.bankBuildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return tables;
}

}  // namespace misalloc
