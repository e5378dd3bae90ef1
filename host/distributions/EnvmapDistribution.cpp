#include "distributions/EnvmapDistribution.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "Constants.h"
#include "Error.h"
#include "distributions/AliasTable.h"

namespace misalloc {
namespace {

double sinThetaOfRow(int row, int height) { return std::sin(kPi * (row + 0.5) / height); }

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
  std::vector<double> weights = sinThetaWeighted(texelLuminance(image), image.width, image.height);
  double total = 0;
  for (double w : weights) total += w;
  return total > 0 ? weights : sphereWeights(image.width, image.height);
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
    tables.cdfStepsRow = binarySearchSteps(image.height);
    tables.cdfStepsCol = binarySearchSteps(image.width);
    storeDrawnProbabilities(tables.cdfTable.data(), image.width, image.height, tables.texels.data() + 3, 4);
  } else {
    tables.cdfTable = {0};
    tables.aliasTable = interleave(buildAliasTable(std::move(weights)));
  }
  return tables;
}

EnvmapTables buildOptimalEnvmapTables(const Envmap& envmap, EnvmapSampler sampler, const BrdfGrid& grid,
                                      const std::array<float, 3>& mirror, const OptimalBankOptions& options) {
  requireValidSize(envmap);
  const RgbImage& image = envmap.image;
  const int width = image.width, height = image.height;
  const std::vector<double> luminance = texelLuminance(image);
  const auto start = std::chrono::steady_clock::now();
  const std::vector<double> weights = sinThetaWeighted(luminance, width, height);
  double total = 0;
  for (double w : weights) total += w;
  if (!(total > 0)) {
    EnvmapTables plain = buildEnvmapTables(envmap, sampler);
    plain.requestedPdf = {EnvmapPdf::Kind::Optimal};
    return plain;
  }

  EnvmapTables tables;
  tables.width = width;
  tables.height = height;
  tables.requestedPdf = tables.pdf = {EnvmapPdf::Kind::Optimal};
  tables.meanLuminance = solidAngleMeanLuminance(luminance, width, height);
  tables.bankShares = options.shares;
  tables.blockLog2 = options.blockLog2;
  const BrdfBins bins = binBrdfs(grid, options.exponentBins, options.diffuseBins);
  tables.brdfBins = int(bins.centres.size());
  tables.brdfBinOfPixel = bins.binOfPixel;
  OptimalBankWeights bank = optimalBlockWeights(weights, width, height, bins, mirror, options);
  tables.bankVariances = bank.variances;

  // Texels: RGB and the probability within the block.
  const int side = 1 << options.blockLog2;
  const int across = (width + side - 1) / side, down = (height + side - 1) / side;
  const std::vector<double>& blockMass = bank.plainBlockMass;
  tables.texels.resize(weights.size() * 4);
#pragma omp parallel for schedule(static)
  for (int row = 0; row < height; ++row) {
    const double* mass = blockMass.data() + std::size_t(row >> options.blockLog2) * across;
    for (int col = 0; col < width; ++col) {
      const std::size_t t = std::size_t(row) * width + col;
      for (int c = 0; c < 3; ++c) tables.texels[4 * t + c] = image.rgb[3 * t + c];
      const double blockWeight = mass[col >> options.blockLog2];
      tables.texels[4 * t + 3] = float(blockWeight > 0 ? weights[t] / blockWeight : 0.0);
    }
  }

  tables.useCdf = sampler == EnvmapSampler::Cdf;
  const std::size_t blocks = blockMass.size(), slotWords = 2 * blocks * side * side;
  const std::size_t cdfSize = std::size_t(down + 1) + std::size_t(down) * (across + 1);
  const std::size_t entries = bank.entries.size();
  tables.aliasTable.assign(slotWords + (tables.useCdf ? 0 : 2 * entries * blocks), 0u);
  writeBlockSlotTables(weights, width, height, options.blockLog2, tables.aliasTable.data());
  tables.blockProbs.assign(entries * blocks, 0.0f);
  if (tables.useCdf) {
    tables.cdfTable.assign(entries * cdfSize, 0.0f);
    tables.cdfStepsRow = binarySearchSteps(down);
    tables.cdfStepsCol = binarySearchSteps(across);
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

}  // namespace misalloc
