// Pairs and quads of pixels that sample one per-pixel table (kernels/pixel_pairs.h): when
// they share, that all build the same table, that the kernels group them as the C++
// reference does, and that the estimate stays unbiased.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>

#include "BiasCheck.h"
#include "KernelCode.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "alloc/GridSearch.h"
#include "render/Render.h"
#include "sampling/HostSampler.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

constexpr int kCells = 32 * 16;  // the default table's: a cell spans Δ = 11.25°

kern::MaVec3 unit(double x, double y, double z) {
  const double l = std::sqrt(x * x + y * y + z * z);
  return kern::makeVec3(float(x / l), float(y / l), float(z / l));
}

// v turned by `degrees` towards the x axis about the axis v × x (v not along x).
kern::MaVec3 turned(kern::MaVec3 v, double degrees) {
  const double a = degrees * kPi / 180;
  // The unit vector in the plane of v and x, orthogonal to v.
  const double d = v.x;
  kern::MaVec3 u = unit(1 - d * v.x, -d * v.y, -d * v.z);
  return unit(std::cos(a) * v.x + std::sin(a) * u.x, std::cos(a) * v.y + std::sin(a) * u.y,
              std::cos(a) * v.z + std::sin(a) * u.z);
}

kern::PixelCdfInputs glossyInputs() {
  kern::PixelCdfInputs in;
  in.brdf = {0.3f, 0.6f, 1e4f};
  in.normal = unit(0.1, 0.2, 1);
  in.mirror = unit(-0.3, 0.4, 1);
  in.envmapShare = 0.5f;
  in.brdfCovers = 1;
  return in;
}

// The table pixel 100 + x samples in a row `width` wide whose quad's pixels have `quad`'s
// inputs and take samples or not, chosen in the order kernels/sample.cl's
// pixelTableGroup and the C++ reference's tableInputs choose it.
kern::TableGroup groupOf(int x, int width, const std::vector<kern::PixelCdfInputs>& quad,
                         const std::vector<int>& samples, int cells = kCells, int pixel = -1) {
  if (pixel < 0) pixel = 100 + x;
  const size_t i = size_t(x - kern::quadFirst(x)), j = i ^ 1, o = size_t(kern::otherPairFirst(x) - kern::quadFirst(x));
  if (kern::pairPartner(x) >= width) return kern::ownTable(pixel, quad[i]);
  const kern::PairTable pair = kern::pairTableOf(quad[i], quad[j], samples[j], cells);
  if (!pair.shares) return kern::ownTable(pixel, quad[i]);
  if (kern::quadPlaces(x, width) < 4) return kern::pairGroup(pixel, x, pair);
  return kern::quadGroup(pixel, x, pair, kern::pairTableOf(quad[o], quad[o + 1], samples[o] && samples[o + 1], cells),
                         cells);
}

// Pixels a and b, places 0 and 1 of a row of two, where b takes samples or not.
bool pairs(const kern::PixelCdfInputs& a, const kern::PixelCdfInputs& b, int bSamples = 1) {
  return groupOf(0, 2, {a, b, a, a}, {1, bSamples, 0, 0}).size == 2;
}

bool sameBits(const kern::PixelCdfInputs& a, const kern::PixelCdfInputs& b) {
  const float fa[] = {a.brdf.rhoD, a.brdf.rhoS, a.brdf.n,   a.normal.x, a.normal.y,
                      a.normal.z,  a.mirror.x,  a.mirror.y, a.mirror.z, a.envmapShare};
  const float fb[] = {b.brdf.rhoD, b.brdf.rhoS, b.brdf.n,   b.normal.x, b.normal.y,
                      b.normal.z,  b.mirror.x,  b.mirror.y, b.mirror.z, b.envmapShare};
  return std::memcmp(fa, fb, sizeof fa) == 0 && a.brdfCovers == b.brdfCovers;
}

}  // namespace

TEST_CASE("two pixels share a table only where their inputs are alike", "[pairs]") {
  const kern::PixelCdfInputs a = glossyInputs();
  CHECK(pairs(a, a));
  // Not a partner without samples.
  CHECK_FALSE(pairs(a, a, 0));
  // One draws BRDF samples and the other none: the table's plain share differs, and
  // without it the second's texels that eq. 6 clips could not be drawn.
  kern::PixelCdfInputs b = a;
  b.brdfCovers = 0;
  CHECK_FALSE(pairs(a, b));
  // The envmap share within 1/16.
  b = a, b.envmapShare = 0.55f;
  CHECK(pairs(a, b));
  b.envmapShare = 0.57f;
  CHECK_FALSE(pairs(a, b));
  // Each BRDF parameter within 5 % of the pair's mean.
  for (float kern::PhongParams::*p : {&kern::PhongParams::rhoD, &kern::PhongParams::rhoS, &kern::PhongParams::n}) {
    b = a, b.brdf.*p = a.brdf.*p * 1.045f;
    CHECK(pairs(a, b));
    b.brdf.*p = a.brdf.*p * 1.06f;
    CHECK_FALSE(pairs(a, b));
  }
  // Normals within Δ/4 = 2.81°.
  b = a, b.normal = turned(a.normal, 2.7);
  CHECK(pairs(a, b));
  b.normal = turned(a.normal, 2.9);
  CHECK_FALSE(pairs(a, b));
  // Mirror directions within the lobe's width as the table spreads it: √(1/n + Δ²/12),
  // 3.29° at n = 10⁴, 18.1° at n = 10.
  b = a, b.mirror = turned(a.mirror, 3.2);
  CHECK(pairs(a, b));
  b.mirror = turned(a.mirror, 3.4);
  CHECK_FALSE(pairs(a, b));
  kern::PixelCdfInputs rough = a;
  rough.brdf.n = 10;
  b = rough, b.mirror = turned(a.mirror, 17.5);
  CHECK(pairs(rough, b));
  b.mirror = turned(a.mirror, 18.7);
  CHECK_FALSE(pairs(rough, b));
}

TEST_CASE("both pixels of a pair build the same table", "[pairs]") {
  // Inputs scattered about one pixel's: whichever pixel asks, the answer and the mean
  // are the same, bit for bit.
  const kern::PixelCdfInputs a = glossyInputs();
  int paired = 0;
  for (uint32_t i = 0; i < 400; ++i) {
    const kern::MaRandom4 r = kern::philoxDraw(0x9a1, 0, 17u, 3u, i);
    auto unitFloat = [&](int k) { return (double(r.v[k]) + 0.5) / 4294967296.0; };
    kern::PixelCdfInputs b = a;
    b.normal = turned(a.normal, 4 * unitFloat(0));
    b.mirror = turned(a.mirror, 5 * unitFloat(1));
    b.brdf.n = float(a.brdf.n * (0.94 + 0.12 * unitFloat(2)));
    b.envmapShare = float(0.4 + 0.2 * unitFloat(3));
    const bool ab = pairs(a, b);
    CHECK(ab == pairs(b, a));
    paired += ab;
    CHECK(sameBits(kern::meanTableInputs(a, b), kern::meanTableInputs(b, a)));
  }
  // Both answers come up.
  CHECK(paired > 20);
  CHECK(paired < 380);
}

TEST_CASE("four pixels share a table where both pairs and their means are alike", "[pairs]") {
  const kern::PixelCdfInputs a = glossyInputs();
  auto at = [&](double degrees) {
    kern::PixelCdfInputs b = a;
    b.normal = turned(a.normal, degrees);
    return b;
  };
  // Normals at 0°, 1°, 1.5°, 2.5° along one arc: pairs 1° apart, their means 1.5°.
  const std::vector<kern::PixelCdfInputs> quad = {a, at(1), at(1.5), at(2.5)};
  const std::vector<int> all = {1, 1, 1, 1};
  const kern::TableGroup g = groupOf(0, 8, quad, all);
  CHECK(g.first == 100);
  CHECK(g.size == 4);
  CHECK(sameBits(g.inputs,
                 kern::meanTableInputs(kern::meanTableInputs(quad[0], quad[1]), kern::meanTableInputs(quad[2], quad[3]))));
  // Every pixel of the quad samples the same table, bit for bit, from its own place.
  for (int x = 1; x < 4; ++x) {
    const kern::TableGroup other = groupOf(x, 8, quad, all);
    CHECK(other.first == 100);
    CHECK(other.size == 4);
    CHECK(sameBits(other.inputs, g.inputs));
  }
  // At 0°, 1°, 3°, 4° the pairs' means lie 3° apart, past Δ/4 = 2.81°: two pairs.
  const std::vector<kern::PixelCdfInputs> apart = {a, at(1), at(3), at(4)};
  for (int x = 0; x < 4; ++x) {
    const kern::TableGroup pair = groupOf(x, 8, apart, all);
    CHECK(pair.size == 2);
    CHECK(pair.first == 100 + (x & ~1));
    CHECK(sameBits(pair.inputs, kern::meanTableInputs(apart[size_t(x & ~1)], apart[size_t(x | 1)])));
  }
  // A pixel of the quad that takes no samples leaves its partner alone and the other pair.
  const std::vector<int> third = {1, 1, 0, 1};
  CHECK(groupOf(0, 8, quad, third).size == 2);
  CHECK(groupOf(3, 8, quad, third).size == 1);
  // A row that ends within the quad (6 wide: places 4 and 5) pairs them at most.
  CHECK(groupOf(4, 6, quad, all).size == 2);
  CHECK(groupOf(5, 6, quad, all).first == 104);
  CHECK(groupOf(4, 5, quad, all).size == 1);
}

namespace {

// Whether quad q of pairedScene shares one table where its counts allow.
bool alikeQuad(int q) { return q % 3 == 0; }

// A scene of random frames in which pixel 2k + 1 is pixel 2k turned by a little (they
// pair) or by too much (every third pair), with an exponent 3 % apart; and in every
// third quad, pixels 1, 2 and 3 are pixel 0 turned by 1°, 1.5° and 2.5° (the quad
// shares), their exponents 1 % apart.
Scene pairedScene(const std::string& map, int width, int height, bool product) {
  Scene scene =
      smallScene(map, "uniform:0.3,0.6,200", width, height, false, EnvmapSampler::Alias, 0, "optimal-pixel", product);
  giveRandomFrames(scene, 11);
  auto turn = [&](int from, int to, double degrees, float exponent) {
    const PixelFrame& f = scene.geometry.pixels[size_t(from)];
    const kern::MaVec3 n = turned(kern::makeVec3(f.normal[0], f.normal[1], f.normal[2]), degrees);
    const kern::MaVec3 m = turned(kern::makeVec3(f.mirror[0], f.mirror[1], f.mirror[2]), degrees);
    scene.geometry.pixels[size_t(to)] = {{n.x, n.y, n.z}, {m.x, m.y, m.z}};
    scene.grid.pixels[size_t(to)].n = scene.grid.pixels[size_t(from)].n * exponent;
  };
  for (int p = 0; p + 1 < scene.pixelCount(); p += 2) {
    const int x = p % width, quad = p / 4;
    if (alikeQuad(quad) && x % 4 == 0 && x + 3 < width) {
      turn(p, p + 1, 1.0, 1.01f);
      turn(p, p + 2, 1.5, 1.02f);
      turn(p, p + 3, 2.5, 1.03f);
      p += 2;
    } else {
      turn(p, p + 1, (p / 2) % 3 == 2 ? 6.0 : 1.0, 1.03f);
    }
  }
  scene.surfaces = labelSurfaces(scene.geometry, scene.grid);
  return scene;
}

}  // namespace

TEST_CASE("pairs of pixels sample one table on PoCL as on the C++ reference, bit for bit", "[pairs][sampler]") {
  // sampleStage runs the stages that keep running sums; samplePixelStage, on a CPU, the
  // others, where a pair in adjacent lanes builds its table once. Background among the
  // pixels, and counts that differ between pairs and within every fifth.
  for (bool product : {false, true}) {
    Scene scene = pairedScene("venice_sunset", 24, 16, product);
    giveBackground(scene, 7);
    StagePlan plan = singleStagePlan(scene, Method::Equal, 40);
    const int M = plan.techniqueCount;
    for (int p = 0; p < scene.pixelCount(); ++p) {
      int32_t* n = plan.counts.data() + size_t(p) * M;
      // A quad that may share takes its first pair's counts.
      const int pair = alikeQuad(p / 4) ? p / 4 * 2 : p / 2, product = M == 3 ? 5 : 0;
      n[0] = 10 + (pair * 7) % 20 + (pair % 5 == 4 ? p % 2 : 0);
      // Every seventh pair: one pixel draws no BRDF samples, the other two, at envmap
      // shares 1/16 apart.
      if (pair % 7 == 6) n[0] = 40 - product - 2 * (p % 2);
      n[1] = 40 - product - n[0];
      if (M == 3) n[2] = product;
    }
    leaveOutBackground(scene, plan.counts);
    // How the pixels that take samples share tables in this plan: in quads, in pairs and
    // alone, each more than a few times.
    int groups[5] = {0, 0, 0, 0, 0};
    const int width = scene.grid.width;
    for (int p = 0; p < scene.pixelCount(); ++p) {
      const int x = p % width, first = p - x + kern::quadFirst(x);
      std::vector<kern::PixelCdfInputs> quad(4);
      std::vector<int> samples(4, 0);
      for (int i = 0; i < kern::quadPlaces(x, width); ++i)
        std::tie(quad[size_t(i)], samples[size_t(i)]) = stageCdfInputs(scene, plan, first + i, product);
      if (samples[size_t(x - kern::quadFirst(x))]) ++groups[groupOf(x, width, quad, samples, scene.tables.pixelCells, p).size];
    }
    INFO("alone " << groups[1] << ", in pairs " << groups[2] << ", in quads " << groups[4]);
    CHECK(groups[1] > 10);
    CHECK(groups[2] > 10);
    CHECK(groups[4] > 10);
    // Running sums; and `exact`'s pilot, whose stored samples carry the pdfs of the
    // group's table under each share (its share columns), without the product, which
    // kernel = reference crosses with them.
    SamplerConfig shareColumns{Estimator::MultiSample, 0, 40, kDefaultGridSize};
    shareColumns.shareColumns = true;
    std::vector<SamplerConfig> configs = {{Estimator::MultiSample, MA_STATS_TECHNIQUE | MA_STATS_LINEAR, 0}};
    if (!product) configs.push_back(shareColumns);
    for (const SamplerConfig& config : configs) {
      Sampler device(testDevice(), scene, config);
      HostSampler host(scene, config);
      size_t mismatches = 0;
      for (int stage = 0; stage < 2; ++stage) {
        StagePlan s = plan;
        s.keepStatistics = stage == 0;
        s.samplesBefore = 40 * stage;
        for (size_t i = 0; i < plan.counts.size(); ++i) s.firstIndex[i] = uint32_t(plan.counts[i] * stage);
        mismatches += stageMismatches(device.run(s, 7), host.run(s, 7));
      }
      mismatches += differingValues(device.storedSamples(), host.storedSamples());
      INFO("product " << product << ", share columns " << config.shareColumns);
      CHECK(mismatches == 0);
    }
  }
}
