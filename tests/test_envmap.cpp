// makeEnvmap, the alias table and the envmap's sampling tables, checked through the
// kernels' own functions (KernelCode.h): the pdf the kernels evaluate is normalised,
// the texels they draw follow it, and a texel of zero weight is never drawn.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "Constants.h"
#include "Error.h"
#include "KernelCode.h"
#include "Statistics.h"
#include "distributions/AliasTable.h"
#include "distributions/EnvmapDistribution.h"
#include "sampling/KernelViews.h"
#include "scene/Envmap.h"

namespace kern = misalloc::kern;
using Catch::Matchers::Contains;
using misalloc::Envmap;
using misalloc::EnvmapSampler;
using misalloc::EnvmapTables;
using misalloc::kPi;
using misalloc::RgbImage;
using misalloc::test::ChiSquare;

namespace {

constexpr double kFloatRounding = 0x1p-24;  // relative error of one rounding to float
constexpr double kDoubleRounding = 0x1p-53;
constexpr double kGrid24 = 0x1p24;  // uniformFloat's values are k / 2^24

// The view the renderer hands the kernels; the maps here keep their image radiance.
kern::EnvmapView viewOf(const EnvmapTables& tables) { return misalloc::makeEnvmapView(tables, -1); }

// Shading points of the optimal pdf per pixel: a head-on diffuse-and-glossy pixel, a
// near-mirror lobe (n = 1e5) seen at a grazing angle from a tilted normal, a black BRDF
// (the plain table), a normal facing the map's lower half, and the envmap shares at
// both ends.
struct PixelOptimalPoint {
  const char* name;
  kern::PhongParams brdf;
  kern::MaVec3 normal, mirror;
  float share;
};

std::vector<PixelOptimalPoint> pixelOptimalPoints() {
  const kern::MaVec3 up = kern::makeVec3(0, 0, 1);
  const kern::MaVec3 tilted = kern::makeVec3(0.8660254f, 0, 0.5f);  // 60° from the zenith
  const kern::MaVec3 grazing = kern::makeVec3(-0.0871557f, 0, 0.9961947f);
  return {
      {"head-on glossy", {0.5f, 0.5f, 20.0f}, up, up, 0.5f},
      {"near-mirror n 1e5 from a tilted normal", {0.0f, 1.0f, 1e5f}, tilted, grazing, 0.25f},
      {"black BRDF", {0.0f, 0.0f, 1.0f}, up, up, 0.5f},
      {"normal facing down", {0.8f, 0.2f, 5.0f}, kern::makeVec3(0, 0, -1), kern::makeVec3(0, 0, -1), 0.75f},
      {"envmap share 1", {0.3f, 0.7f, 50.0f}, tilted, up, 1.0f},
      {"envmap share 0", {0.3f, 0.7f, 50.0f}, tilted, up, 0.0f},
  };
}

// Whether a stage of envmap share C draws BRDF samples, without the product technique.
bool drawsBrdf(float share) { return share < 1.0f; }

// The view of `point`'s own table for a stage of envmap share C, in `rows`; with
// productCdf, the product technique's CDF beside it (kernels/pixel_optimal.h). The
// stage draws BRDF samples where brdfCovers says so, by default where C < 1.
kern::EnvmapView pixelOptimalView(const EnvmapTables& tables, const PixelOptimalPoint& point, float share,
                                  bool shareColumns, std::vector<int>& rows, bool productCdf = false,
                                  std::optional<bool> brdfCovers = {}) {
  kern::EnvmapView view = viewOf(tables);
  rows.assign(MA_PIXEL_CDF_ROWS(tables.pixelCells, productCdf, shareColumns), 0);
  kern::buildPixelOptimalCdf(tables.blockProbs.data(), tables.pixelCells, point.brdf, point.normal, point.mirror, share,
                             brdfCovers.value_or(drawsBrdf(share)) ? 1 : 0, shareColumns ? 1 : 0, productCdf ? 1 : 0,
                             rows.data(), 1);
  view.pixelCdf = rows.data();
  return view;
}

// The texel that kernels/envmap.h's sampleEnvmap picks for these random numbers.
int sampledTexel(const kern::EnvmapView& view, const kern::MaRandom4& r) { return kern::sampleEnvmap(view, r).texel; }

// `samples` texels drawn by `draw` (by default the kernels' sampleEnvmap) with Philox
// keyed (seedLo, seedHi): none of probability 0, and a χ² test against p at `level`.
void checkDrawnTexels(const kern::EnvmapView& view, const std::vector<double>& p, uint64_t samples, uint32_t seedLo,
                      uint32_t seedHi, double level, const std::function<int(const kern::MaRandom4&)>& draw = {}) {
  std::vector<uint64_t> counts(p.size(), 0);
  for (uint64_t i = 0; i < samples; ++i) {
    const kern::MaRandom4 r = kern::philoxDraw(seedLo, seedHi, 0, 0, uint32_t(i));
    ++counts[draw ? draw(r) : sampledTexel(view, r)];
  }
  uint64_t zeroWeightDraws = 0;
  for (std::size_t t = 0; t < p.size(); ++t) zeroWeightDraws += p[t] == 0 ? counts[t] : 0;
  CHECK(zeroWeightDraws == 0);
  ChiSquare test = misalloc::test::chiSquare(counts, p, samples);
  INFO("chi^2 = " << test.statistic << " with " << test.degreesOfFreedom << " degrees of freedom");
  if (test.degreesOfFreedom > 0) CHECK(test.pValue() > level);
}

// ∫ p dω of the pdf that envmapLookup reads, by the midpoint rule on a grid 4 times the
// map's resolution (the map's own above 100 000 texels).
double midpointPdfIntegral(const kern::EnvmapView& view) {
  const int k = double(view.width) * view.height > 100000 ? 1 : 4;
  const int nu = k * view.width, nv = k * view.height;
  double integral = 0;
  for (int j = 0; j < nv; ++j) {
    double v = (j + 0.5) / nv;
    double rowWeight = 2 * kPi * kPi * std::sin(kPi * v) / (double(nu) * nv);
    for (int i = 0; i < nu; ++i)
      integral += kern::envmapLookup(view, kern::latLongDirection(float((i + 0.5) / nu), float(v))).pdf * rowWeight;
  }
  return integral;
}

std::vector<double> texelProbabilities(const EnvmapTables& tables) {
  std::vector<double> p(tables.texels.size() / 4);
  for (std::size_t t = 0; t < p.size(); ++t) p[t] = tables.texels[4 * t + 3];
  return p;
}

// Grey texels of the given luminance.
Envmap greyMap(int width, int height, const std::function<float(int col, int row)>& luminance) {
  Envmap map;
  map.image = {width, height, std::vector<float>(std::size_t(width) * height * 3)};
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col)
      for (int c = 0; c < 3; ++c) map.image.rgb[3 * (std::size_t(row) * width + col) + c] = luminance(col, row);
  map.description = "synthetic";
  return map;
}

struct NamedMap {
  std::string name;
  Envmap map;
};

// Small synthetic maps for the edge cases, two procedural ones and the real map of
// the highest contrast.
const std::vector<NamedMap>& testMaps() {
  static const std::vector<NamedMap> maps = [] {
    std::vector<NamedMap> m;
    m.push_back({"1x1", greyMap(1, 1, [](int, int) { return 2.0f; })});
    m.push_back({"2x1", greyMap(2, 1, [](int col, int) { return col == 0 ? 1.0f : 3.0f; })});
    m.push_back(
        {"single bright texel", greyMap(8, 4, [](int col, int row) { return col == 5 && row == 1 ? 10.0f : 0.0f; })});
    m.push_back(
        {"black upper hemisphere", greyMap(8, 4, [](int col, int row) { return row < 2 ? 0.0f : 1.0f + col; })});
    m.push_back({"all black", greyMap(8, 4, [](int, int) { return 0.0f; })});
    // Zero weight at both ends of the rows and columns and in between.
    m.push_back({"zero rows and columns", greyMap(7, 5, [](int col, int row) {
                   return row == 0 || row == 2 || row == 4 || col == 0 || col == 3 || col == 6 ? 0.0f
                                                                                               : float(col + row);
                 })});
    // Irregular weights whose sums round, a third of them zero, and zero trailing rows
    // and columns: the prefix sums must still reach exactly 1 where the weights end.
    m.push_back({"sparse", greyMap(61, 29, [](int col, int row) {
                   uint32_t hash = uint32_t(col * 7919 + row * 104729) * 2654435761u;
                   bool zero = hash % 3 == 0 || col >= 58 || row >= 27;
                   return zero ? 0.0f : float(hash >> 8) / float(1 << 24);
                 })});
    m.push_back({"sun", misalloc::makeEnvmap("sun", 64)});
    m.push_back({"cosk:3", misalloc::makeEnvmap("cosk:3", 64)});
    m.push_back({"rooitou_park", misalloc::makeEnvmap(MISALLOC_SOURCE_DIR "/data/envmaps/rooitou_park.exr")});
    return m;
  }();
  return maps;
}

// How many of the 2^24 values k / 2^24 of uniformFloat lie below x ∈ [0, 1].
double gridCountBelow(float x) { return std::ceil(double(x) * kGrid24); }

// The probability that mul_hi(bits, n) picks bucket i for uniform 32-bit `bits`: the
// bits from ceil(i 2^32 / n) up to ceil((i + 1) 2^32 / n).
double aliasBucketProbability(uint64_t i, uint64_t n) {
  auto firstBits = [n](uint64_t bucket) { return ((bucket << 32) + n - 1) / n; };
  return double(firstBits(i + 1) - firstBits(i)) / 0x1p32;
}

// The exact probability of each texel under the kernels' samplers, from the stored
// tables and the discrete uniforms they draw: alias buckets from mul_hi of 32 bits,
// coins and CDF lookups from 24-bit uniformFloat, with searchCdf picking the last i
// with cdf[i] ≤ u (checked on its own below).
std::vector<double> kernelTexelDistribution(const EnvmapTables& tables) {
  const std::size_t n = std::size_t(tables.width) * tables.height;
  std::vector<double> p(n, 0.0);
  if (tables.useCdf) {
    const float* marginal = tables.cdfTable.data();
    for (int row = 0; row < tables.height; ++row) {
      double rowP = (gridCountBelow(marginal[row + 1]) - gridCountBelow(marginal[row])) / kGrid24;
      const float* conditional = marginal + (tables.height + 1) + std::size_t(row) * (tables.width + 1);
      for (int col = 0; col < tables.width; ++col)
        p[std::size_t(row) * tables.width + col] =
            rowP * (gridCountBelow(conditional[col + 1]) - gridCountBelow(conditional[col])) / kGrid24;
    }
    return p;
  }
  for (std::size_t i = 0; i < n; ++i) {
    double bucketP = aliasBucketProbability(i, n);
    float acceptance;
    std::memcpy(&acceptance, &tables.aliasTable[2 * i], sizeof acceptance);
    double accept = std::min(gridCountBelow(acceptance), kGrid24) / kGrid24;
    p[i] += bucketP * accept;
    p[tables.aliasTable[2 * i + 1]] += bucketP * (1 - accept);
  }
  return p;
}

double totalVariation(const std::vector<double>& p, const std::vector<double>& q) {
  double sum = 0;
  for (std::size_t i = 0; i < p.size(); ++i) sum += std::abs(p[i] - q[i]);
  return sum;
}

}  // namespace

TEST_CASE("kern::rowOfIndex is the integer quotient over the sizes the tables allow", "[envmap]") {
  // Every side up to 2^22 - 1 and every index below 2^29 (buildEnvmapTables refuses more):
  // the rows next to each multiple of n, where a float quotient rounds across it.
  for (int n : {1, 2, 3, 7, 512, 1000, 1023, 1024, 4095, 8191, 65535, 1 << 21, (1 << 22) - 1}) {
    const int64_t last = (int64_t(1) << 29) - 1;
    const int64_t rows = std::min<int64_t>(last / n, (1 << 22) - 1);
    for (int64_t q : {int64_t(0), int64_t(1), rows / 3, rows / 2, rows - 1, rows})
      for (int64_t i = q * n - 2; i <= q * n + 2; ++i)
        if (i >= 0 && i <= last && i / n < (1 << 22)) CHECK(kern::rowOfIndex(int(i), n) == int(i / n));
  }
}

TEST_CASE("kern::searchCdf returns the last index i with cdf[i] <= u", "[envmap]") {
  // Every CDF of n ≤ 9 steps over the values {0, 0.25, 0.5, 1} (ties and jumps at
  // both ends), probed at each value it holds and between them.
  const float levels[] = {0.0f, 0.25f, 0.5f, 1.0f};
  const float probes[] = {0.0f, 0.1f, 0.25f, 0.3f, 0.5f, 0.7f, 0.99999994f};
  for (int n = 1; n <= 9; ++n) {
    int steps = 0;
    while ((1 << steps) < n) ++steps;
    std::vector<int> level(n + 1, 0);  // nondecreasing level indices, cdf[n] = 1
    level[n] = 3;
    std::function<void(int)> enumerate = [&](int i) {
      if (i == n) {
        std::vector<float> cdf(n + 1);
        for (int k = 0; k <= n; ++k) cdf[k] = levels[level[k]];
        for (float u : probes) {
          int expected = 0;
          for (int k = 0; k < n; ++k)
            if (cdf[k] <= u) expected = k;
          INFO("n = " << n << ", u = " << u);
          CHECK(kern::searchCdf(cdf.data(), n, steps, u) == expected);
        }
        return;
      }
      for (int l = level[i - 1]; l <= 3; ++l) {
        level[i] = l;
        enumerate(i + 1);
      }
    };
    level[0] = 0;
    enumerate(1);
  }
}

TEST_CASE("kern::searchCdf takes every written-out step up to MA_MAX_CDF_STEPS", "[envmap]") {
  // A uniform CDF over n = 2^k entries, k = 10 … 16, each a multiple of 2^-k (exact in
  // float): u = (i + f)/n lies in entry i, which only the search's last step decides
  // for odd i.
  for (int steps = 10; steps <= MA_MAX_CDF_STEPS; ++steps) {
    const int n = 1 << steps;
    std::vector<float> cdf(n + 1);
    for (int i = 0; i <= n; ++i) cdf[i] = float(i) / float(n);
    for (int i : {0, 1, n / 2 - 1, n / 2 + 1, n - 3, n - 1})
      for (double f : {0.0, 0.5}) {
        const float u = float((i + f) / n);
        INFO("n = " << n << ", u = " << u);
        CHECK(kern::searchCdf(cdf.data(), n, steps, u) == i);
      }
  }
}

TEST_CASE("buildEnvmapTables lays out the tables that kernels/envmap.h reads", "[envmap]") {
  Envmap map = greyMap(5, 3, [](int col, int row) { return float(1 + col + 10 * row); });
  map.image.rgb[0] = 7.0f;  // R of texel 0 differs from G and B
  for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
    EnvmapTables tables = misalloc::buildEnvmapTables(map, sampler);
    CHECK(tables.width == 5);
    CHECK(tables.height == 3);
    CHECK_FALSE(tables.uniformFallback);
    REQUIRE(tables.texels.size() == 4 * 15);
    for (std::size_t t = 0; t < 15; ++t)
      for (int c = 0; c < 3; ++c) CHECK(tables.texels[4 * t + c] == map.image.rgb[3 * t + c]);
    // Texel (col, row) has weight luminance × sin θ at its centre.
    double luminance0 = misalloc::luminance(7, 1, 1);
    double weight0 = luminance0 * std::sin(kPi / 6), weight14 = 25 * std::sin(5 * kPi / 6);
    // The CDF sampler's probabilities are what its float CDFs draw (checked below).
    if (sampler == EnvmapSampler::Alias)
      CHECK(tables.texels[4 * 14 + 3] / tables.texels[3] == Approx(weight14 / weight0).epsilon(4 * kFloatRounding));
    if (sampler == EnvmapSampler::Alias) {
      CHECK_FALSE(tables.useCdf);
      CHECK(tables.aliasTable.size() == 2 * 15);
      CHECK(tables.cdfTable == std::vector<float>{0.0f});
    } else {
      CHECK(tables.useCdf);
      REQUIRE(tables.cdfTable.size() == 4 + 3 * 6);
      CHECK(tables.aliasTable == std::vector<uint32_t>{0});
      CHECK(tables.cdfStepsRow == 2);
      CHECK(tables.cdfStepsCol == 3);
      for (int row = 0; row <= 3; ++row) {
        const float* cdf = row == 0 ? &tables.cdfTable[0] : &tables.cdfTable[4 + (row - 1) * 6];
        int n = row == 0 ? 3 : 5;
        CHECK(cdf[0] == 0.0f);
        CHECK(cdf[n] == 1.0f);
        for (int i = 0; i < n; ++i) CHECK(cdf[i] < cdf[i + 1]);
      }
    }
  }
  EnvmapTables one = misalloc::buildEnvmapTables(greyMap(1, 1, [](int, int) { return 1.0f; }), EnvmapSampler::Cdf);
  CHECK(one.cdfStepsRow == 0);
  CHECK(one.cdfStepsCol == 0);
  EnvmapTables real = misalloc::buildEnvmapTables(testMaps().back().map, EnvmapSampler::Cdf);
  CHECK(real.cdfStepsRow == 9);
  CHECK(real.cdfStepsCol == 10);
}

TEST_CASE("buildEnvmapTables falls back to uniform sampling only for a black map", "[envmap]") {
  for (const auto& [name, map] : testMaps()) {
    INFO(name);
    EnvmapTables tables = misalloc::buildEnvmapTables(map, EnvmapSampler::Alias);
    CHECK(tables.uniformFallback == (name == "all black"));
  }
  EnvmapTables black = misalloc::buildEnvmapTables(greyMap(8, 4, [](int, int) { return 0.0f; }), EnvmapSampler::Alias);
  for (int row = 0; row < 4; ++row) {
    double expected = std::sin(kPi * (row + 0.5) / 4) / (8 * (2 * std::sin(kPi / 8) + 2 * std::sin(3 * kPi / 8)));
    CHECK(black.texels[4 * (8 * row + 3) + 3] == Approx(expected).epsilon(4 * kFloatRounding));
    CHECK(black.texels[4 * (8 * row + 3)] == 0.0f);  // the radiance stays black
  }
}

TEST_CASE("buildEnvmapTables rejects maps the kernels cannot index", "[envmap]") {
  Envmap huge;
  huge.image.width = 32768;
  huge.image.height = 16384;  // 2^29 texels, 2^31 floats: one past the kernels' int range
  huge.description = "huge.exr";
  CHECK_THROWS_AS(misalloc::buildEnvmapTables(huge, EnvmapSampler::Alias), misalloc::InputError);
  CHECK_THROWS_WITH(misalloc::buildEnvmapTables(huge, EnvmapSampler::Alias),
                    Contains("huge.exr") && Contains("too many"));
  Envmap empty;
  CHECK_THROWS_AS(misalloc::buildEnvmapTables(empty, EnvmapSampler::Alias), std::invalid_argument);
  Envmap negative = greyMap(2, 1, [](int col, int) { return col == 0 ? 1.0f : -1.0f; });
  CHECK_THROWS_AS(misalloc::buildEnvmapTables(negative, EnvmapSampler::Cdf), std::invalid_argument);
  // The CDF sampler's search is written out for 2^MA_MAX_CDF_STEPS columns at most; the
  // alias sampler takes a wider map.
  const int widest = 1 << MA_MAX_CDF_STEPS;
  Envmap wide = greyMap(widest + 1, 1, [](int, int) { return 1.0f; });
  CHECK_THROWS_WITH(misalloc::buildEnvmapTables(wide, EnvmapSampler::Cdf),
                    Contains(std::to_string(widest + 1) + " columns of texels") && Contains("alias"));
  CHECK_NOTHROW(misalloc::buildEnvmapTables(wide, EnvmapSampler::Alias));
  CHECK_NOTHROW(misalloc::buildEnvmapTables(greyMap(widest, 1, [](int, int) { return 1.0f; }), EnvmapSampler::Cdf));
}

TEST_CASE("texel probabilities sum to 1 and both samplers' agree", "[envmap]") {
  for (const auto& [name, map] : testMaps()) {
    INFO(name);
    EnvmapTables alias = misalloc::buildEnvmapTables(map, EnvmapSampler::Alias);
    EnvmapTables cdf = misalloc::buildEnvmapTables(map, EnvmapSampler::Cdf);
    for (std::size_t i = 0; i < alias.texels.size(); ++i)
      if (i % 4 != 3) CHECK(alias.texels[i] == cdf.texels[i]);
    // The CDF sampler stores what its float CDFs draw: one float rounding and one 2^-24
    // grid step per CDF value away from the weights' probabilities.
    CHECK(totalVariation(texelProbabilities(alias), texelProbabilities(cdf)) <=
          3 * kFloatRounding * (alias.width + alias.height));
    std::vector<double> p = texelProbabilities(alias);
    double sum = 0;
    for (double x : p) sum += x;
    // Each probability is rounded to float once; the double sums add ~N ulps.
    CHECK(std::abs(sum - 1) <= kFloatRounding + double(p.size()) * kDoubleRounding);
  }
}

TEST_CASE("the envmap pdf the kernels evaluate integrates to 1 over the sphere", "[envmap]") {
  for (const auto& [name, map] : testMaps()) {
    INFO(name);
    EnvmapTables tables = misalloc::buildEnvmapTables(map, EnvmapSampler::Alias);
    kern::EnvmapView view = viewOf(tables);
    // The midpoint rule in (u, v), dω = 2π² sin θ du dv, with k × k points inside each
    // texel: p sin θ is constant on a texel, so the rule is exact up to the rounding
    // of a few float operations per point (P, the factor W H / 2π², sin θ, one division).
    const int k = tables.width * tables.height > 100000 ? 2 : 4;
    const int nu = k * tables.width, nv = k * tables.height;
    double integral = 0;
    for (int j = 0; j < nv; ++j) {
      double v = (j + 0.5) / nv;
      double rowWeight = 2 * kPi * kPi * std::sin(kPi * v) / (double(nu) * nv);
      for (int i = 0; i < nu; ++i) {
        double u = (i + 0.5) / nu;
        integral += kern::envmapLookup(view, kern::latLongDirection(float(u), float(v))).pdf * rowWeight;
      }
    }
    CHECK(std::abs(integral - 1) <= 16 * kFloatRounding);
  }
}

TEST_CASE("envmapLookup at a texel's centre returns that texel's radiance and pdf", "[envmap]") {
  for (const auto& [name, map] : testMaps()) {
    INFO(name);
    EnvmapTables tables = misalloc::buildEnvmapTables(map, EnvmapSampler::Cdf);
    kern::EnvmapView view = viewOf(tables);
    int mismatches = 0;
    for (int row = 0; row < tables.height; ++row) {
      for (int col = 0; col < tables.width; ++col) {
        float u = (col + 0.5f) / tables.width, v = (row + 0.5f) / tables.height;
        kern::EnvmapHit hit = kern::envmapLookup(view, kern::latLongDirection(u, v));
        const float* texel = &tables.texels[4 * (std::size_t(row) * tables.width + col)];
        double pdf = texel[3] * double(tables.width) * tables.height / (2 * kPi * kPi * std::sin(kPi * v));
        bool same = hit.r == texel[0] && hit.g == texel[1] && hit.b == texel[2] &&
                    std::abs(hit.pdf - pdf) <= 16 * kFloatRounding * pdf;
        mismatches += same ? 0 : 1;
      }
    }
    CHECK(mismatches == 0);
  }
}

TEST_CASE("the kernels' samplers draw texels with the stored probabilities, never one of weight 0", "[envmap]") {
  // The compensated pdf ([Kar19] eq. 14) zeroes every texel at or below the mean. One χ²
  // test per pdf, map and sampler; a false alarm in any of them with probability 2 %.
  const double level = misalloc::test::sidakLevel(0.02, int(2 * 2 * testMaps().size()));
  for (const std::string pdf : {"plain", "compensated"})
    for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
      const bool cdf = sampler == EnvmapSampler::Cdf;
      for (const auto& [name, map] : testMaps()) {
        INFO(name << (cdf ? ", CDF, " : ", alias, ") << pdf);
        EnvmapTables tables = misalloc::buildEnvmapTables(map, sampler, misalloc::parseEnvmapPdf(pdf));
        std::vector<double> p = texelProbabilities(tables);

        // Exactly, over every value of the random numbers. The CDF sampler stores the
        // probabilities it draws, rounded to float once. Each acceptance probability is
        // off by at most one float rounding and one step of the 2^-24 grid, and
        // mul_hi's buckets are uniform only when N divides 2^32.
        std::vector<double> exact = kernelTexelDistribution(tables);
        double bucketBias = 0;
        for (std::size_t i = 0; i < p.size(); ++i)
          bucketBias += std::abs(aliasBucketProbability(i, p.size()) - 1.0 / p.size());
        double bound = cdf ? kFloatRounding : 3 * kFloatRounding + bucketBias;
        CHECK(totalVariation(exact, p) <= bound);
        for (std::size_t t = 0; t < p.size(); ++t)
          if (p[t] == 0) CHECK(exact[t] == 0);

        // Statistically, through the kernels' functions and random numbers.
        checkDrawnTexels(viewOf(tables), p, 1000000, 0x5eed, cdf ? 1 : 0, level);
      }
    }
}

TEST_CASE("the optimal pdf's bank draws texels with the probabilities it evaluates, which integrate to 1",
          "[envmap][optimal]") {
  // [Kar19] eq. 9 per BRDF bin and envmap share (host/distributions/OptimalBank.h): a block by
  // the entry's table, then a texel of the block by the plain weights. The first and the
  // last entry of each map and sampler; a false alarm in any χ² test with probability 2 %.
  const misalloc::BrdfGrid grid = misalloc::makeBrdfGrid("seed000", 8, 8);
  const std::array<float, 3> mirror = {-0.5f, 0.0f, 0.8660254f};  // a view 30° off the normal
  const double level = misalloc::test::sidakLevel(0.02, int(2 * 2 * testMaps().size()));
  for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf})
    for (const auto& [name, map] : testMaps()) {
      EnvmapTables tables = misalloc::buildOptimalEnvmapTables(map, sampler, grid, mirror);
      INFO(name << (sampler == EnvmapSampler::Cdf ? ", CDF" : ", alias"));
      CHECK(tables.requestedPdf.optimal());
      if (name == "all black") {
        CHECK_FALSE(tables.hasBank());  // falls back to the plain (uniform) tables
        continue;
      }
      REQUIRE(tables.hasBank());
      CHECK(tables.brdfBins > 1);
      kern::EnvmapView view = viewOf(tables);
      for (int entry : {0, tables.brdfBins * tables.bankShares - 1}) {
        INFO("entry " << entry);
        view.bankEntry = entry;
        std::vector<double> p(std::size_t(tables.width) * tables.height);
        double sum = 0;
        for (std::size_t t = 0; t < p.size(); ++t) sum += p[t] = kern::texelProbability(view, int(t));
        // A block's and a texel's probability, each rounded to float, and their product.
        CHECK(std::abs(sum - 1) <= 8 * kFloatRounding + double(p.size()) * kDoubleRounding);

        checkDrawnTexels(view, p, 200000, 0x0b7, uint32_t(entry), level);

        // The pdf a BRDF-sampled direction reads, by the midpoint rule (as for the plain pdf).
        CHECK(std::abs(midpointPdfIntegral(view) - 1) <= 32 * kFloatRounding);
      }
    }
}

// The product technique from the pixel's cells (kernels/product.h, ProductView::pixelCells):
// texel t's probability under it and the texel it draws, as estimator.h reads and draws.
double productTexelProbability(const kern::EnvmapView& env, int t) {
  kern::ProductView product{};
  product.pixelCells = 1;
  const float sinTheta = 0.5f;  // any: the pdf is the probability over the same Jacobian
  return double(kern::productPdf(env, product, {}, t, 0.0f, sinTheta)) / kern::envmapPdfOfTexel(env, 1.0f, sinTheta);
}

int productDrawnTexel(const kern::EnvmapView& env, const kern::MaRandom4& r) {
  kern::ProductView product{};
  product.pixelCells = 1;
  return kern::sampleProduct(env, product, {}, r, 0.0f).texel;
}

// The texel probabilities of a pixel's table: the envmap's, or the product's.
std::vector<double> pixelTexelProbabilities(const kern::EnvmapView& view, bool product) {
  std::vector<double> p(std::size_t(view.width) * view.height);
  for (std::size_t t = 0; t < p.size(); ++t)
    p[t] = product ? productTexelProbability(view, int(t)) : kern::texelProbability(view, int(t));
  return p;
}

TEST_CASE(
    "the optimal pdf per pixel draws texels with the probabilities it evaluates, positive wherever the map is lit "
    "and no BRDF sample covers it",
    "[envmap][optimal][product]") {
  // kernels/pixel_optimal.h: a cell by the pixel's own CDF, built from its normal, mirror
  // direction, BRDF and envmap share, then a texel of the cell by the plain weights, at
  // every shading point of pixelOptimalPoints; and the product technique's CDF built
  // beside it (eq. 6 at C = 1), drawn and evaluated as kernels/product.h does. A false
  // alarm in any χ² test with probability 2 %.
  const std::vector<PixelOptimalPoint> points = pixelOptimalPoints();
  const double level = misalloc::test::sidakLevel(0.02, int(2 * std::size(points) * testMaps().size()));
  std::size_t clippedLit = 0;  // lit texels that a table of C < 1 leaves to BRDF sampling
  for (const auto& [name, map] : testMaps()) {
    EnvmapTables tables = misalloc::buildPixelOptimalEnvmapTables(map);
    INFO(name);
    CHECK(tables.requestedPdf.pixelOptimal());
    if (name == "all black") {
      CHECK(tables.pixelCells == 0);  // falls back to the plain (uniform) tables
      continue;
    }
    REQUIRE(tables.pixelCells > 0);
    CHECK(tables.pixelCells <= MA_MAX_PIXEL_CELLS);
    const std::vector<double> plain = misalloc::plainTexelWeights(map.image);
    for (const PixelOptimalPoint& point : points) {
      INFO(point.name);
      std::vector<int> rows, withProduct, atShareOne;
      kern::EnvmapView view = pixelOptimalView(tables, point, point.share, false, rows);
      // The product's CDF leaves the envmap's as it was, bit for bit.
      const kern::EnvmapView both = pixelOptimalView(tables, point, point.share, false, withProduct, true);
      CHECK(std::equal(rows.begin(), rows.end(), withProduct.begin()));
      const kern::EnvmapView product = kern::pixelProductView(both);
      for (bool isProduct : {false, true}) {
        INFO((isProduct ? "the product's table" : "the envmap's table"));
        const std::vector<double> p = pixelTexelProbabilities(isProduct ? both : view, isProduct);
        // Where the stage draws BRDF samples (C < 1) the envmap's table is eq. 6's alone and
        // the product's f/F alone: a lit texel may be left out only with its cell, which
        // eq. 6 clips or the product's cells miss, and BRDF sampling covers. At C = 1 the
        // plain share keeps it drawable.
        const bool brdfCovers = drawsBrdf(point.share);
        const kern::EnvmapView& table = isProduct ? product : view;
        double sum = 0;
        std::size_t unlit = 0;
        for (std::size_t t = 0; t < p.size(); ++t) {
          sum += p[t];
          const bool clipped = brdfCovers && kern::pixelCellProbability(table, kern::blockOfTexel(table, int(t))) == 0;
          unlit += plain[t] > 0 && !(p[t] > 0) && !clipped;
          clippedLit += plain[t] > 0 && clipped;
        }
        // A cell's and a texel's probability, each rounded to float, and their product.
        CHECK(std::abs(sum - 1) <= 8 * kFloatRounding + double(p.size()) * kDoubleRounding);
        CHECK(unlit == 0);
        const uint32_t seedHi = uint32_t(&point - points.data()) + (isProduct ? 0x100u : 0u);
        if (isProduct)
          checkDrawnTexels(both, p, 200000, 0x9e1, seedHi, level,
                           [&](const kern::MaRandom4& r) { return productDrawnTexel(both, r); });
        else
          checkDrawnTexels(view, p, 200000, 0x9e1, seedHi, level);
      }
      // The pdf a BRDF-sampled direction reads, by the midpoint rule.
      CHECK(std::abs(midpointPdfIntegral(view) - 1) <= 32 * kFloatRounding);
      // The product is the envmap's table at C = 1, f/F ([CL18] from the cells), with the
      // stage's plain share, its chunks' masses rounded apart: each cell within a few steps
      // of the CDF's grid.
      const kern::EnvmapView shareOne =
          pixelOptimalView(tables, point, 1.0f, false, atShareOne, false, drawsBrdf(point.share));
      double worst = 0;
      for (int c = 0; c < tables.pixelCells; ++c)
        worst = std::max(
            worst, std::abs(double(kern::pixelCellProbability(product, c)) - kern::pixelCellProbability(shareOne, c)));
      CHECK(worst <= 8 / kGrid24);
    }
  }
  CHECK(clippedLit > 0);  // no plain share beside BRDF sampling
}

TEST_CASE("the optimal pdf per pixel's share columns hold the pdfs of the tables built for their shares",
          "[envmap][optimal]") {
  // The grid search of `exact` judges each α_0 by a stored sample's pdf under the share
  // nearest it (kernels/stats.h's share columns), which pixelSharePdfs reads from the
  // cells' masses kept beside the stage's own table. At every texel, each must be the pdf of the
  // table that a stage of that share builds, up to the rounding of that table's CDF
  // entries to the uniform's grid (the scales sum eq. 6 in the stage's order): a cell's
  // probability within 8 steps of the grid, as the product's test above bounds it
  // (32 × 16 cells, 32 to a chunk, came within 4.1 steps; 16 × 8 within 4).
  for (const auto& [name, map] : testMaps()) {
    EnvmapTables tables = misalloc::buildPixelOptimalEnvmapTables(map);
    if (tables.pixelCells == 0) continue;  // the black map's plain tables
    INFO(name);
    for (const PixelOptimalPoint& point : pixelOptimalPoints()) {
      INFO(point.name);
      std::vector<int> stageRows;
      const kern::EnvmapView stage = pixelOptimalView(tables, point, point.share, true, stageRows);
      for (int share = 0; share < MA_MAX_BANK_SHARES; ++share) {
        INFO("share " << kern::columnShare(share));
        std::vector<int> rows;
        const kern::EnvmapView built = pixelOptimalView(tables, point, kern::columnShare(share), false, rows);
        const float sinTheta = 0.5f, perProbability = kern::envmapPdfOfTexel(built, 1.0f, sinTheta);
        std::size_t mismatches = 0, positive = 0;
        for (int t = 0; t < tables.width * tables.height; ++t) {
          float pdfs[MA_MAX_BANK_SHARES];
          kern::pixelSharePdfs(stage, t, sinTheta, pdfs);
          const double expected = kern::envmapPdfOfTexel(built, kern::texelProbability(built, t), sinTheta);
          const double slack = 1e-4 * expected + perProbability * tables.texels[4 * t + 3] * 8 / kGrid24;
          mismatches += !(std::abs(pdfs[share] - expected) <= slack);
          positive += expected > 0;
        }
        CHECK(mismatches == 0);
        CHECK(positive > 0);
      }
    }
  }
}

TEST_CASE("the optimal pdf per pixel keeps its cells within what its search reaches, on any map's shape",
          "[envmap][optimal]") {
  // A map taller than wide would otherwise give more cells than searchPixelCdf's steps
  // reach: the last cells could never be drawn, though the pdf counts them.
  for (int cellsAcross = misalloc::kMinPixelCellsAcross; cellsAcross <= misalloc::kMaxPixelCellsAcross;
       cellsAcross *= 2)
    for (auto [width, height] :
         {std::pair{1024, 512}, std::pair{16, 1024}, std::pair{1, 4096}, std::pair{4096, 4096}}) {
      const int log2 = misalloc::pixelCellLog2(width, height, cellsAcross);
      const int64_t across = (width + (1 << log2) - 1) >> log2, down = (height + (1 << log2) - 1) >> log2;
      INFO(width << "x" << height << ", " << cellsAcross << " across: 2^" << log2 << " texels a side");
      CHECK(log2 >= 1);
      CHECK(across <= cellsAcross);
      CHECK(across * down <= MA_MAX_PIXEL_CELLS);
    }
  CHECK(misalloc::pixelCellLog2(1024, 512, 16) == 6);                                  // 16 × 8 cells
  CHECK(misalloc::pixelCellLog2(1024, 512, misalloc::kDefaultPixelCellsAcross) == 5);  // 32 × 16
  CHECK(misalloc::pixelCellLog2(1024, 512, misalloc::kMaxPixelCellsAcross) == 4);      // 64 × 32
  // A tall map's texels are drawn with the probabilities the pdf gives them: 8 × 256
  // cells of 4 × 4 texels, the most the search reaches.
  const Envmap tall = greyMap(32, 1024, [](int col, int row) { return float(1 + (col + 3 * row) % 7); });
  EnvmapTables tables = misalloc::buildPixelOptimalEnvmapTables(tall);
  REQUIRE(tables.pixelCells == MA_MAX_PIXEL_CELLS);
  kern::EnvmapView view = viewOf(tables);
  std::vector<int> rows(MA_PIXEL_CDF_ROWS(tables.pixelCells, 0, 0));
  const kern::MaVec3 up = kern::makeVec3(0, 0, 1);
  kern::buildPixelOptimalCdf(tables.blockProbs.data(), tables.pixelCells, {0.5f, 0.5f, 20.0f}, up, up, 0.5f, 1, 0, 0,
                             rows.data(), 1);
  view.pixelCdf = rows.data();
  std::vector<double> p(std::size_t(tables.width) * tables.height);
  for (std::size_t t = 0; t < p.size(); ++t) p[t] = kern::texelProbability(view, int(t));
  checkDrawnTexels(view, p, 200000, 0x7a1, 1, 0.001);
}

TEST_CASE("the optimal pdf per pixel's CDF runs over its cells chunk by chunk, each cell once", "[envmap][optimal]") {
  // kernels/pixel_layout.h: chunk j holds cells j, j + 16, ...; the CDF takes chunk 0's
  // cells, then chunk 1's, ... The search returns the cell at the position it finds and
  // the pdf reads a cell's entries at its position: both must be one bijection, also
  // where the cells are fewer than the chunks or no multiple of them (maps of any size).
  for (int count : {1, 8, 15, 16, 17, 20, 128, 320, 512, 513, 2047, 2048}) {
    INFO("cells " << count);
    std::vector<int> cellAt(std::size_t(count), -1);
    for (int c = 0; c < count; ++c) {
      const int p = kern::cdfPositionOfCell(count, c);
      REQUIRE((p >= 0 && p < count));
      CHECK(cellAt[std::size_t(p)] == -1);
      cellAt[std::size_t(p)] = c;
      CHECK(kern::cellAtCdfPosition(count, p) == c);
    }
    // Each chunk's cells take consecutive positions, in increasing order, from its start.
    int p = 0;
    for (int j = 0; j < MA_PIXEL_CHUNKS; ++j) {
      CHECK(kern::chunkStart(count, j) == p);
      for (int i = 0; i < kern::chunkLength(count, j); ++i, ++p)
        CHECK(cellAt[std::size_t(p)] == i * MA_PIXEL_CHUNKS + j);
    }
    CHECK(p == count);
  }
}

TEST_CASE("the optimal pdf per pixel weighs a Phong lobe by its mass over a cell, not by its value at the centre",
          "[envmap][optimal]") {
  // kernels/pixel_optimal.h, cellLobe: summed over the cells, each cell's solid angle
  // times its lobe keeps the lobe's mass 2π/(n+1). Up to the cells' quadrature (a few %)
  // where the lobe is wider than a cell; where it is narrower, within what sampling a
  // lobe of the cell's own spread at the cells' spacing allows (√12 spreads apart: 0.35–2.0
  // on a square grid). The lobe's value at the centres misses a narrow lobe's mass by
  // orders of magnitude, either way (0 or 200× at n = 10⁴): the case this exists for.
  EnvmapTables tables = misalloc::buildPixelOptimalEnvmapTables(misalloc::makeEnvmap("constant", 1024), 16);
  REQUIRE(tables.pixelCells == 16 * 8);
  auto cell = [&](int c) { return kern::pixelCellAt(tables.blockProbs.data(), tables.pixelCells, c); };
  auto centre = [&](int c) { return cell(c).area.centre; };
  auto normalised = [](double x, double y, double z) {
    double r = std::sqrt(x * x + y * y + z * z);
    return kern::makeVec3(float(x / r), float(y / r), float(z / r));
  };
  // A cell's centre, the corner that four cells share at the equator, and directions
  // spread over the sphere by a fixed Fibonacci lattice.
  const int c0 = 3 * 16 + 5;
  const kern::MaVec3 a = centre(c0), b = centre(c0 + 1), c = centre(c0 + 16), d = centre(c0 + 17);
  std::vector<kern::MaVec3> mirrors = {a,
                                       normalised(a.x + b.x + c.x + d.x, a.y + b.y + c.y + d.y, a.z + b.z + c.z + d.z)};
  for (int i = 0; i < 48; ++i) {
    double z = 1 - (i + 0.5) / 24, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = i * kPi * (3 - std::sqrt(5.0));
    mirrors.push_back(normalised(r * std::cos(phi), r * std::sin(phi), z));
  }
  for (float n : {0.0f, 1.0f, 10.0f, 100.0f, 1e3f, 1e4f, 1e5f}) {
    INFO("n = " << n);
    const kern::PhongParams brdf = {0.0f, 1.0f, n};
    for (const kern::MaVec3& mirror : mirrors) {
      INFO("mirror " << mirror.x << ", " << mirror.y << ", " << mirror.z);
      double mass = 0;
      for (int k = 0; k < tables.pixelCells; ++k)
        mass += double(cell(k).solidAngle) * kern::cellLobe(brdf, cell(k).area, mirror);
      const double ratio = mass / (2 * kPi / (double(n) + 1));
      if (n <= 10.0f)
        CHECK(std::abs(ratio - 1) <= 0.1);
      else
        CHECK((ratio >= 0.3 && ratio <= 2.5));
    }
  }
  // On every test map, down to cells of one texel, under either frame, the lobe is a number.
  for (const auto& [name, map] : testMaps()) {
    INFO(name);
    EnvmapTables small = misalloc::buildPixelOptimalEnvmapTables(map);
    for (int k = 0; k < small.pixelCells; ++k)
      for (float n : {0.0f, 1.0f, 1e5f}) {
        const kern::PixelCell c = kern::pixelCellAt(small.blockProbs.data(), small.pixelCells, k);
        for (const kern::CellFrame& frame : {c.area, c.light}) {
          const float lobe = kern::cellLobe({0.0f, 1.0f, n}, frame, frame.centre);
          CHECK((std::isfinite(lobe) && lobe > 0.0f));
        }
      }
  }
}

TEST_CASE("the optimal pdf per pixel weighs cos θ by its mean over a cell, the part above the horizon kept",
          "[envmap][optimal]") {
  // kernels/pixel_optimal.h, cellCosine: against each cell's mean of max(0, cos θ) over
  // its texels (weighed by solid angle), at normals spread over the sphere, the error
  // weighed by the cells' solid angles (relative to ∫ max(0, cos θ) dω = π). The value at
  // the centre errs by 2.1–3.5 % per normal, mostly where a cell straddles the horizon;
  // the mean by about 2 %, where the cosine curves within a cell wholly above it.
  const int width = 256, height = 128;
  EnvmapTables tables = misalloc::buildPixelOptimalEnvmapTables(misalloc::makeEnvmap("constant", width), 16);
  REQUIRE(tables.pixelCells == 16 * 8);
  const int side = 1 << tables.blockLog2;
  double totalMean = 0, totalCentre = 0;
  for (int i = 0; i < 24; ++i) {
    const double z = 1 - (i + 0.5) / 12, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = i * kPi * (3 - std::sqrt(5.0));
    const kern::MaVec3 normal = kern::makeVec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
    std::vector<double> mean(std::size_t(tables.pixelCells), 0.0), weight(mean.size(), 0.0);
    for (int row = 0; row < height; ++row)
      for (int col = 0; col < width; ++col) {
        const kern::MaVec3 w = kern::latLongDirection(float((col + 0.5) / width), float((row + 0.5) / height));
        const double dOmega = std::sin(kPi * (row + 0.5) / height);
        const std::size_t cell = std::size_t(row / side) * (width / side) + col / side;
        mean[cell] += dOmega * std::max(0.0f, kern::dot3(normal, w));
        weight[cell] += dOmega;
      }
    double errorMean = 0, errorCentre = 0;
    for (int k = 0; k < tables.pixelCells; ++k) {
      const kern::PixelCell cell = kern::pixelCellAt(tables.blockProbs.data(), tables.pixelCells, k);
      const double exact = mean[std::size_t(k)] / weight[std::size_t(k)];
      errorMean += cell.solidAngle * std::abs(kern::cellCosine(normal, cell.area) - exact);
      errorCentre += cell.solidAngle * std::abs(std::max(0.0f, kern::dot3(normal, cell.area.centre)) - exact);
    }
    CHECK(errorMean / kPi <= 0.025);
    totalMean += errorMean;
    totalCentre += errorCentre;
  }
  CHECK(totalMean <= 0.8 * totalCentre);
}

TEST_CASE("the optimal pdf per pixel takes f's mass at a cell's light and p_ρ's over the cell", "[envmap][optimal]") {
  // buildPixelOptimalEnvmapTables, cellFrames: a patch of 2 × 2 texels 10⁴ times brighter
  // than the rest, in a corner of a cell 16 texels wide, and a lobe narrower than the
  // cell (n = 10³) aimed at the patch. Against the sums over the cell's texels: f's mass
  // (cellIntegrand; their plain masses times ρ and cos), within 2×, and p_ρ's
  // (pixelCellMasses' q; their solid angles times p_ρ), within 4× (0.35×: a lobe at a
  // cell's corner is no Gaussian of the cell's spread). f's mass at the cell's centre
  // and size misses the patch by two orders of magnitude (0.01×: its corner lies 0.25
  // rad from the centre, in the lobe's far tail); p_ρ's mass at the light's frame is the
  // lobe's peak over the whole cell, far too much, which clips the cell from the
  // pixel's table (eq. 6) where BRDF sampling covers only a part of it.
  const int width = 256, height = 128, row0 = 48, col0 = 80;
  auto bright = [&](int col, int row) { return (row == row0 || row == row0 + 1) && (col == col0 || col == col0 + 1); };
  const Envmap map = greyMap(width, height, [&](int col, int row) { return bright(col, row) ? 1e4f : 1.0f; });
  EnvmapTables tables = misalloc::buildPixelOptimalEnvmapTables(map, 16);
  REQUIRE(tables.blockLog2 == 4);
  const int cellIndex = (row0 >> 4) * (width >> 4) + (col0 >> 4);
  const kern::PixelCell cell = kern::pixelCellAt(tables.blockProbs.data(), tables.pixelCells, cellIndex);
  const kern::MaVec3 patch = kern::latLongDirection(float(col0 + 1) / width, float(row0 + 1) / height);
  // The light's centre within a texel (π/128 = 0.025 rad) of the patch's.
  CHECK(kern::dot3(cell.light.centre, patch) >= std::cos(kPi / height));
  double plainTotal = 0, f = 0, q = 0;
  const kern::PhongParams brdf = {0.0f, 1.0f, 1e3f};
  const double texelArea = (2 * kPi / width) * (kPi / height);
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col) {
      const double sinTheta = std::sin(kPi * (row + 0.5) / height);
      const double weight = (bright(col, row) ? 1e4 : 1.0) * sinTheta;
      plainTotal += weight;
      if (row >> 4 != row0 >> 4 || col >> 4 != col0 >> 4) continue;
      const kern::MaVec3 w = kern::latLongDirection(float((col + 0.5) / width), float((row + 0.5) / height));
      const float lobe = kern::phongLobe(brdf, w, patch), cosine = std::max(0.0f, kern::dot3(patch, w));
      f += weight * kern::phongBrdf(brdf, lobe) * cosine;
      q += sinTheta * texelArea * kern::brdfPdfOf(brdf, cosine, lobe);
    }
  f /= plainTotal;
  const kern::CellMasses masses =
      kern::pixelCellMasses(tables.blockProbs.data(), tables.pixelCells, cellIndex, brdf, patch, patch);
  INFO("f: the cell's over the texels' " << masses.f / f << "; p_ρ: " << masses.q / q);
  CHECK(masses.f == kern::cellIntegrand(cell, brdf, patch, patch));
  CHECK((masses.f / f >= 0.5 && masses.f / f <= 2.0));
  CHECK((masses.q / q >= 0.25 && masses.q / q <= 4.0));
}

TEST_CASE("the optimal pdf per pixel clips a cell by p_ρ's mass where its light lies, not over the whole cell",
          "[envmap][optimal]") {
  // Eq. 6 is a pointwise max(0, f/F − (1−C) p_ρ/B); a cell's term is its integral. A dim
  // cell (0.1 of a map of 1) holds a patch of 2 × 2 texels 20 times the map; a diffuse
  // BRDF faces it, C = 1/2. Pointwise, the patch stays (20 > 1/2) and the rest of the
  // cell is clipped (0.1 < 1/2). Over the whole cell, p_ρ's mass outweighs f's and the
  // cell would be clipped to 0; its peak (buildPixelOptimalEnvmapTables: the texels over
  // twice its mean light per solid angle) keeps it, against the sum over its texels
  // within 10 %.
  const int width = 256, height = 128, row0 = 54, col0 = 86;
  auto inCell = [&](int col, int row) { return row >> 4 == row0 >> 4 && col >> 4 == col0 >> 4; };
  auto radiance = [&](int col, int row) {
    if ((row == row0 || row == row0 + 1) && (col == col0 || col == col0 + 1)) return 20.0f;
    return inCell(col, row) ? 0.1f : 1.0f;
  };
  const Envmap map = greyMap(width, height, radiance);
  EnvmapTables tables = misalloc::buildPixelOptimalEnvmapTables(map, 16);
  REQUIRE(tables.blockLog2 == 4);
  const int cellIndex = (row0 >> 4) * (width >> 4) + (col0 >> 4);
  const kern::PhongParams diffuse = {1.0f, 0.0f, 1.0f};
  const kern::MaVec3 normal = kern::latLongDirection(float(col0 + 1) / width, float(row0 + 1) / height);
  const float C = 0.5f;
  // Every texel's f and p_ρ mass, f in the cells' units (plain shares times ρ cos).
  const double texelArea = (2 * kPi / width) * (kPi / height);
  double plainTotal = 0;
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col) plainTotal += radiance(col, row) * std::sin(kPi * (row + 0.5) / height);
  std::vector<std::array<double, 3>> texels;  // f, p_ρ, in the cell (1) or not (0)
  double F = 0, B = 0;
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col) {
      const double sinTheta = std::sin(kPi * (row + 0.5) / height);
      const kern::MaVec3 w = kern::latLongDirection(float((col + 0.5) / width), float((row + 0.5) / height));
      const float cosine = std::max(0.0f, kern::dot3(normal, w));
      const double f = radiance(col, row) * sinTheta / plainTotal * kern::phongBrdf(diffuse, 0.0f) * cosine;
      const double q = sinTheta * texelArea * kern::brdfPdfOf(diffuse, cosine, 0.0f);
      texels.push_back({f, q, inCell(col, row) ? 1.0 : 0.0});
      F += f, B += q;
    }
  double pointwise = 0, whole[2] = {0, 0};
  for (const auto& [f, q, cell] : texels)
    if (cell > 0) pointwise += std::max(0.0, f / F - (1 - C) * q / B), whole[0] += f / F, whole[1] += (1 - C) * q / B;
  REQUIRE(whole[0] < whole[1]);  // the whole cell's masses alone would clip it
  REQUIRE(pointwise > 0);
  kern::PixelOptimalTerms terms;
  terms.invF = float(1 / F), terms.brdfScale = float((1 - C) / B), terms.lit = 1;
  const float peakLight =
      kern::cellField(tables.blockProbs.data(), tables.pixelCells, cellIndex, kern::CELL_PEAK_LIGHT);
  const float peakGap = kern::cellField(tables.blockProbs.data(), tables.pixelCells, cellIndex, kern::CELL_PEAK_GAP);
  const float term = kern::eq6Value(float(whole[0] * F), float(whole[1] / (1 - C) * B), peakLight, peakGap, terms);
  INFO("the cell's eq. 6 term over its texels': " << term / pointwise << " (peak: light " << peakLight << ", gap "
                                                  << peakGap << ")");
  CHECK(std::abs(term / pointwise - 1) <= 0.1);
}

TEST_CASE("sampleEnvmap returns a direction inside the texel it drew", "[envmap]") {
  // Up to the float rounding of (col + u) / W and of the direction's components.
  const double slack = 8 * kFloatRounding * 2 * kPi;
  for (const auto& [name, map] : testMaps()) {
    for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
      INFO(name);
      EnvmapTables tables = misalloc::buildEnvmapTables(map, sampler);
      kern::EnvmapView view = viewOf(tables);
      int outside = 0;
      for (uint32_t i = 0; i < 100000; ++i) {
        kern::MaRandom4 r = kern::philoxDraw(0xd1ec, 7, 1, 0, i);
        int t = sampledTexel(view, r);
        kern::EnvmapSample sample = kern::sampleEnvmap(view, r);
        REQUIRE(sample.texel == t);
        kern::MaVec3 w = sample.w;
        double theta = std::atan2(std::hypot(double(w.x), double(w.y)), double(w.z));
        double phi = std::atan2(double(w.y), double(w.x));
        int row = t / tables.width, col = t % tables.width;
        double thetaLo = kPi * row / tables.height, thetaHi = kPi * (row + 1) / tables.height;
        // φ from the texel's first edge, wrapped into [−slack, 2π − slack).
        double dPhi = phi - 2 * kPi * col / tables.width;
        dPhi -= 2 * kPi * std::floor((dPhi + slack) / (2 * kPi));
        bool inside = theta >= thetaLo - slack && theta <= thetaHi + slack && dPhi >= -slack &&
                      dPhi <= 2 * kPi / tables.width + slack;
        outside += inside ? 0 : 1;
      }
      CHECK(outside == 0);
    }
  }
}

TEST_CASE("buildAliasTable reproduces extreme weights and never returns a zero", "[envmap][alias]") {
  // Weights over 600 orders of magnitude, with zeros, and one bucket holding almost
  // all of the mass, as a small bright sun does.
  std::vector<double> weights(100000);
  for (std::size_t i = 0; i < weights.size(); ++i)
    weights[i] = i % 3 == 0 ? 0.0 : std::ldexp(1.0 + double(i % 7), int(i % 2001) - 1000);
  weights[777] = 1e300;
  misalloc::AliasTable table = misalloc::buildAliasTable(weights);
  const std::size_t n = weights.size();
  REQUIRE(table.probability.size() == n);
  REQUIRE(table.alias.size() == n);
  double total = 0;
  for (double w : weights) total += w;
  std::vector<double> implied(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    REQUIRE(table.alias[i] < n);
    implied[i] += table.probability[i] / double(n);
    implied[table.alias[i]] += (1 - double(table.probability[i])) / double(n);
    if (weights[i] == 0) {
      CHECK(table.probability[i] == 0.0f);
      CHECK(weights[table.alias[i]] > 0);
    }
  }
  // Each acceptance probability is rounded to float once, moving at most 2^-24 / N
  // between a bucket and its alias.
  std::vector<double> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = weights[i] / total;
  CHECK(totalVariation(implied, p) <= 2 * kFloatRounding);
}

TEST_CASE("buildAliasTable rejects weights that are no distribution", "[envmap][alias]") {
  using misalloc::buildAliasTable;
  CHECK_THROWS_AS(buildAliasTable({}), std::invalid_argument);
  CHECK_THROWS_AS(buildAliasTable({0.0, 0.0}), std::invalid_argument);
  CHECK_THROWS_AS(buildAliasTable({1.0, -1.0}), std::invalid_argument);
  CHECK_THROWS_AS(buildAliasTable({1.0, std::nan("")}), std::invalid_argument);
  CHECK_THROWS_AS(buildAliasTable({1.0, std::numeric_limits<double>::infinity()}), std::invalid_argument);
  CHECK_THROWS_AS(buildAliasTable({1e308, 1e308}), std::invalid_argument);  // the sum overflows
}

TEST_CASE("makeEnvmap reads an EXR path", "[envmap]") {
  const std::string path = MISALLOC_SOURCE_DIR "/data/envmaps/lebombo.exr";
  Envmap map = misalloc::makeEnvmap(path);
  CHECK(map.image.width == 1024);
  CHECK(map.image.height == 512);
  CHECK(map.coskExponent < 0);
  CHECK_THAT(map.description, Contains("lebombo.exr (1024×512)"));
}

TEST_CASE("makeEnvmap rasterises constant and cos^K maps", "[envmap]") {
  Envmap one = misalloc::makeEnvmap("constant");
  CHECK(one.image.width == 512);
  CHECK(one.image.height == 256);
  CHECK(one.coskExponent < 0);
  CHECK(one.image.rgb == std::vector<float>(512 * 256 * 3, 1.0f));
  Envmap two = misalloc::makeEnvmap("constant:2.5", 16);
  CHECK(two.image.rgb == std::vector<float>(16 * 8 * 3, 2.5f));
  CHECK(two.description == "constant:2.5 (16×8)");

  for (double k : {0.0, 1.0, 7.5}) {
    INFO("K = " << k);
    const int width = 64, height = 32;
    Envmap map = misalloc::makeEnvmap(fmt::format("cosk:{}", k), width);
    CHECK(map.coskExponent == float(k));
    for (int row = 0; row < height; ++row) {
      const float* first = &map.image.rgb[3 * std::size_t(row) * width];
      CHECK(std::count(first, first + 3 * width, first[0]) == 3 * width);  // grey, constant along the row
      // The solid-angle average of c^K, c = cos θ, over the row (c from c1 to c0):
      // ∫ c^K dc / (c0 − c1) = (c0^{K+1} − c1^{K+1}) / ((K+1)(c0 − c1)), with c1 ≥ 0.
      double c0 = std::cos(kPi * row / height), c1 = std::max(0.0, std::cos(kPi * (row + 1) / height));
      double exact = row < height / 2 ? (std::pow(c0, k + 1) - std::pow(c1, k + 1)) / ((k + 1) * (c0 - c1)) : 0.0;
      // The 16-point midpoint rule in c errs by at most (Δc/16)² max|f''| / 24, with
      // f'' = K(K−1) c^{K−2} largest at c0 for K ≥ 2 and 0 for K = 0 and 1.
      double step = (c0 - c1) / 16;
      double ruleError = row < height / 2 && k >= 2 ? step * step / 24 * k * (k - 1) * std::pow(c0, k - 2) : 0.0;
      CHECK(std::abs(first[0] - exact) <= ruleError + 2 * kFloatRounding * exact);
    }
    CHECK(map.image.rgb[3 * std::size_t(height / 2 - 1) * width] > 0.0f);  // the horizon row keeps its upper part
  }
}

TEST_CASE("makeEnvmap's sun keeps its power at any size and resolution", "[envmap]") {
  // The sky depends on θ only, so the texel diametrically opposite in φ holds the sky
  // without the sun; the excess power over the cap's solid angle is the sun's radiance.
  auto sunRadiance = [](double radiusDegrees, int width) {
    Envmap map = misalloc::makeEnvmap(fmt::format("sun:40,90,{},1e5", radiusDegrees), width);
    const RgbImage& im = map.image;
    auto luminance = [&](int col, int row) {
      const float* p = &im.rgb[3 * (std::size_t(row) * im.width + col)];
      return misalloc::luminance(p[0], p[1], p[2]);
    };
    double excess = 0;
    for (int row = 0; row < im.height; ++row) {
      double solidAngle =
          2 * kPi / im.width * (std::cos(kPi * row / im.height) - std::cos(kPi * (row + 1) / im.height));
      for (int col = 0; col < im.width; ++col)
        excess += (luminance(col, row) - luminance((col + im.width / 2) % im.width, row)) *
                  (std::abs(col - im.width / 4) < im.width / 4 ? solidAngle : 0.0);
    }
    double radius = radiusDegrees * kPi / 180;
    return excess / (2 * kPi * (1 - std::cos(radius)));
  };
  double reference = sunRadiance(0.5, 512);
  for (auto [radius, width] : {std::pair{0.05, 64}, {0.5, 64}, {3.0, 64}, {0.05, 512}, {3.0, 512}, {0.5, 2048}}) {
    INFO("radius " << radius << "°, width " << width);
    // The disc's texels are rounded to float once each.
    CHECK(sunRadiance(radius, width) == Approx(reference).epsilon(16 * kFloatRounding));
  }

  const int width = 512, height = 256;
  Envmap sun = misalloc::makeEnvmap("sun", width);
  const auto& rgb = sun.image.rgb;
  auto at = [&](int col, int row, int c) { return rgb[3 * (std::size_t(row) * width + col) + c]; };
  // The brightest texel is one of those the centre (θ = 40°, φ = 90°) touches.
  std::size_t brightest = (std::max_element(rgb.begin(), rgb.end()) - rgb.begin()) / 3;
  CHECK(std::abs((brightest / width + 0.5) * 180.0 / height - 40) <= 180.0 / height);
  CHECK(std::abs((brightest % width + 0.5) * 360.0 / width - 90) <= 360.0 / width);
  // The sky is bluish and brighter towards the horizon; the ground is dimmer than any sky.
  double maxSky = 0;
  for (int row = 0; row < height / 2; ++row) {
    CHECK(at(400, row, 2) > at(400, row, 0));
    if (row > 0) CHECK(at(400, row, 1) > at(400, row - 1, 1));
    maxSky = std::max(maxSky, misalloc::luminance(at(400, row, 0), at(400, row, 1), at(400, row, 2)));
  }
  for (int row = height / 2; row < height; ++row) CHECK(at(400, row, 1) < at(400, 0, 1));
  // RATIO is relative to the sky's brightest radiance, at the horizon; the texels
  // next to it average over π/H of brightness falling at most linearly in 1 − cos θ.
  CHECK(reference / maxSky >= 1e5);
  CHECK(reference / maxSky <= 1e5 / (1 - kPi / height));
}

TEST_CASE("makeEnvmap rejects bad specs, listing the accepted forms", "[envmap]") {
  for (const char* spec : {"", "cosk", "cosk:", "cosk:-1", "cosk:abc", "cosk:1e50", "constant:-2", "constant:1,2",
                           "sun:", "sun:1,2,3", "sun:1,2,3,4,5", "sun:200,0,1,10", "sun:40,90,0,10", "sun:40,90,1,0",
                           "sun:40,90,0.5,1e5x", "sun:40,nan,0.5,10", "no_such_map.exr"}) {
    INFO(spec);
    CHECK_THROWS_AS(misalloc::makeEnvmap(spec), misalloc::InputError);
    CHECK_THROWS_WITH(misalloc::makeEnvmap(spec), Contains("accepted forms") && Contains("cosk:K"));
  }
  CHECK_THROWS_WITH(misalloc::makeEnvmap("constant", 1), Contains("width 1"));
  CHECK_THROWS_AS(misalloc::makeEnvmap("sun", 1 << 20), misalloc::InputError);
}
