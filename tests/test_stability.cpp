// The stability suite: hard scenes and degenerate statistics. Every case checks that
// images, variances and weights are finite, that every α lies on the simplex, that the
// estimate is unbiased (z-scores over fixed seeds against a closed form, or techniques
// against each other where there is none) and that the defensive rules are counted
// (Rendering::fallbackPixels / flooredPixels, EnvmapTables::uniformFallback).
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "BiasCheck.h"
#include "Constants.h"
#include "KernelCode.h"
#include "SceneFixtures.h"
#include "TestBinary.h"
#include "TestDevice.h"
#include "TestSize.h"
#include "paper/MixtureOptimizer.h"
#include "paper/MonteCarloStudy.h"
#include "paper/PaperExamples.h"
#include "render/Render.h"
#include "report/ImageMetrics.h"
#include "scene/ExrIO.h"
#include "stats/PixelStats.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

const std::vector<Method> kAdaptive = {Method::Heuristic, Method::SigmaSqrtC, Method::Linear, Method::Exact};

// On the sweeps' sampler (tests/SceneFixtures.h), or, given a work-group size, on PoCL.
Rendering renderWith(const Scene& scene, Method method, int spp, uint64_t seed, std::vector<double> costs = {},
                     int deviceLocalSize = 0) {
  AdaptiveOptions options;
  options.costs = costs.empty() ? std::vector<double>(scene.techniqueCount(), 1.0) : costs;
  options.oracleSamples = 128;
  const SamplerConfig config = samplerConfigFor(method, Estimator::MultiSample, spp, options, scene.techniqueCount());
  const std::unique_ptr<StageSampler> sampler =
      deviceLocalSize > 0 ? std::make_unique<Sampler>(testDevice(), scene, config, deviceLocalSize)
                          : sweepSampler(scene, config);
  return render(*sampler, method, options, spp, seed);
}

MeanAndError imageMean(const Rendering& r) {
  return pixelMean(std::vector<double>(r.image.rgb.begin(), r.image.rgb.end()));
}

// Finite image and variances, every α on the simplex. Returns the number of bad values.
size_t badValues(const Rendering& r, int M) {
  size_t bad = 0;
  for (float v : r.image.rgb) bad += !std::isfinite(v);
  for (double v : r.variance) bad += !(std::isfinite(v) && v >= 0);
  const size_t pixels = r.alpha.size() / M;
  for (size_t p = 0; p < pixels; ++p) {
    double sum = 0;
    for (int k = 0; k < M; ++k) {
      double a = r.alpha[p * M + k];
      bad += !(std::isfinite(a) && a >= 0 && a <= 1);
      sum += a;
    }
    bad += !(std::abs(sum - 1) <= 1e-12);
  }
  return bad;
}

// Renders with each method, checks every output, and adds to `family` a test of the
// pixel mean against `expected` (closed form) or, when expected is NaN, against the
// first method's mean. At the small test size (the sanitizer build) only the methods in
// `cheap` run, when it is given; each keeps the seed it has in the full sweep.
void checkMethods(BiasFamily& family, const Scene& scene, const std::vector<Method>& methods, int spp, uint64_t seed,
                  double expected, const std::string& what, std::vector<double> costs = {},
                  const std::vector<Method>& cheap = {}) {
  const int M = scene.techniqueCount();
  std::string referenceName;
  MeanAndError reference{expected, 0};
  for (Method m : methods) {
    ++seed;
    if (smallTestSize() && !cheap.empty() && std::find(cheap.begin(), cheap.end(), m) == cheap.end()) continue;
    Rendering r = renderWith(scene, m, spp, seed, costs);
    const MeanAndError e = imageMean(r);
    const std::string name = fmt::format("{} {}", what, methodName(m));
    INFO(fmt::format("{}: fallback {} floored {}", name, r.fallbackPixels, r.flooredPixels));
    CHECK(badValues(r, M) == 0);
    if (std::isfinite(expected)) {
      addEstimate(family, name, e, expected);
    } else if (referenceName.empty()) {
      referenceName = name;
      reference = e;
    } else {
      addAgreement(family, fmt::format("{} against {}", name, referenceName), e, reference);
    }
  }
}

// A lat-long EXR in the temporary directory, for maps no procedural spec describes.
std::string writeMap(const std::string& name, int w, int h, const std::vector<float>& rgb) {
  RgbImage image;
  image.width = w;
  image.height = h;
  image.rgb = rgb;
  std::string path = (std::filesystem::temp_directory_path() / fmt::format("misalloc-stability-{}.exr", name)).string();
  writeExr(path, image);
  return path;
}

bool onSimplex(const std::vector<double>& alpha) {
  double sum = 0;
  for (double a : alpha) {
    if (!(std::isfinite(a) && a >= 0 && a <= 1)) return false;
    sum += a;
  }
  return std::abs(sum - 1) < 1e-9;
}

}  // namespace

// ---------------------------------------------------------------------------------
// BRDF
// ---------------------------------------------------------------------------------

TEST_CASE("fastLog1p and fastExpm1 keep relative precision near 0", "[stability][fastmath]") {
  constexpr double ulp = 1.0 / (1 << 23);
  double worstLog = 0, worstExp = 0;
  for (double x = 1e-30; x < 0.9999; x *= 1.0137) {
    for (double s : {-1.0, 1.0}) {
      float xf = float(s * x);
      double exact = std::log1p(double(xf));
      worstLog = std::max(worstLog, std::abs(kern::fastLog1p(xf) - exact) / std::abs(exact));
    }
  }
  for (double x = 1e-30; x < 80; x *= 1.0137) {
    float xf = float(-x);
    double exact = std::expm1(double(xf));
    worstExp = std::max(worstExp, std::abs(kern::fastExpm1(xf) - exact) / std::abs(exact));
  }
  INFO("log1p " << worstLog / ulp << " ulp, expm1 " << worstExp / ulp << " ulp");
  CHECK(worstLog < 8 * ulp);
  CHECK(worstExp < 8 * ulp);
}

TEST_CASE("the Phong lobe and its sampler keep float precision up to n = 1e5", "[stability][fastmath]") {
  // Sampled directions about an oblique mirror direction: the kernel's cos^n α must
  // match cos^n α of the same float direction computed in double, and u = cos^(n+1) α
  // (the CDF's inverse) must be uniform: mean 1/2, standard error 1/√(12 N).
  double theta = 0.7, phi = 2.1;
  kern::MaVec3 mirror = kern::makeVec3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
                                       float(std::cos(theta)));
  BiasFamily family(0.01, 3);
  for (double n : {1e3, 1e4, 1e5}) {
    kern::PhongParams b{0.0f, 1.0f, float(n)};
    const int N = 200000;
    double worst = 0, sumU = 0;
    std::mt19937 engine{uint32_t(n)};
    for (int i = 0; i < N; ++i) {
      // The kernel's 24-bit uniforms.
      float u1 = kern::uniformFloat(engine()), u2 = kern::uniformFloat(engine());
      kern::MaVec3 w = kern::sampleSpecular(b, kern::frameAbout(mirror), u1, u2);
      // cos α of the float vectors in double, normalising both.
      double wx = w.x, wy = w.y, wz = w.z, mx = mirror.x, my = mirror.y, mz = mirror.z;
      double wn = std::sqrt(wx * wx + wy * wy + wz * wz), mn = std::sqrt(mx * mx + my * my + mz * mz);
      double dx = wx / wn - mx / mn, dy = wy / wn - my / mn, dz = wz / wn - mz / mn;
      double d = 0.5 * (dx * dx + dy * dy + dz * dz);
      double exact = std::exp(n * std::log1p(-d));
      double lobe = kern::phongLobe(b, w, mirror);
      if (exact > 1e-30) worst = std::max(worst, std::abs(lobe - exact) / exact);
      sumU += std::exp((n + 1) * std::log1p(-d));
    }
    // u = 1 − u1 is uniform on {1, 2, …, 2²⁴}/2²⁴: mean 1/2 + 2⁻²⁵.
    family.add(fmt::format("n {}: mean u", n), sumU / N, 0.5 + std::ldexp(1.0, -25), std::sqrt(1.0 / (12.0 * N)));
    INFO(fmt::format("n {}: worst relative lobe error {}", n, worst));
    // |ω − r|²/2 keeps d to a few ulps of itself, so the lobe is within ~1e-5; through
    // 1 − dot(ω, r) (6e-8 absolute in d) it was off by n·6e-8 ≈ 0.6 % at n = 1e5.
    CHECK(worst < 1e-4);
  }
  checkFamily(family);
}

TEST_CASE("near-mirror Phong lobes n = 1e3, 1e4, 1e5 with rhoS = 1 are unbiased", "[stability]") {
  // View along the normal: [HS14] eq. 6.17 is exact. Envmap-only sampling of a lobe of
  // solid angle ~2π/n is too heavy-tailed for a z-test, so it is left out. So are too
  // few envmap samples in the other methods: the part of the integral that MIS leaves
  // to them is found by rare hits of the lobe, and with the 2 + 1 envmap samples an
  // adaptive render of 64 spp takes (a pilot of 5 %), most pixels see none and the
  // pixel mean's sample variance misses that part's spread. 256 spp gives each ~7.
  uint64_t seed = 1000;
  // Heavy-tailed: the adaptive methods leave the lobe's share to rare envmap hits.
  BiasFamily family(0.1, 3 * 2 * 5);
  for (double n : {1e3, 1e4, 1e5}) {
    for (bool split : {false, true}) {
      seed += 10;
      if (smallTestSize() && n != 1e5) continue;  // the small size keeps the sharpest lobe
      Scene scene = smallScene("cosk:1", fmt::format("uniform:0,1,{}", n), 16, 16, split);
      checkMethods(family, scene, {Method::Brdf, Method::Equal, Method::Heuristic, Method::Linear, Method::Exact}, 256,
                   seed, closedForm(0, 1, n, 1), fmt::format("n {} split {}", n, split));
    }
  }
  checkFamily(family);
}

TEST_CASE("a grazing view 1 degree above the horizon: techniques agree", "[stability]") {
  uint64_t seed = 2000;
  BiasFamily family(0.05, 4 + 3);  // each method against equal
  for (double n : {20.0, 1e4}) {
    if (smallTestSize() && n != 1e4) {
      seed += 10;
      continue;
    }
    Scene scene = smallScene("kloofendal_overcast", fmt::format("uniform:0.2,0.8,{}", n), 32, 32, false,
                             EnvmapSampler::Alias, 89.0);
    std::vector<Method> methods = {Method::Equal, Method::Brdf, Method::Heuristic, Method::Linear};
    if (n < 100) methods.push_back(Method::Envmap);
    checkMethods(family, scene, methods, 64, seed += 10, NAN, fmt::format("view 89 n {}", n));
  }
  checkFamily(family);
}

TEST_CASE("lobes partly below the horizon: techniques agree, split or not", "[stability]") {
  // View at 70°: a cos^5 lobe about the mirror direction loses a large share below
  // the horizon; those samples count with f = 0.
  uint64_t seed = 3000;
  BiasFamily family(0.06, 2 * 4);  // each method against equal
  for (bool split : {false, true}) {
    Scene scene = smallScene("constant", "uniform:0.1,0.9,5", 32, 32, split, EnvmapSampler::Cdf, 70.0);
    checkMethods(family, scene, {Method::Equal, Method::Envmap, Method::Brdf, Method::Heuristic, Method::SigmaSqrtC},
                 64, seed += 10, NAN, fmt::format("view 70 split {}", split));
  }
  checkFamily(family);
}

TEST_CASE("pure diffuse rhoD = 1: closed form, and BRDF sampling of a constant map is exact", "[stability]") {
  uint64_t seed = 4000;
  Scene cosk = smallScene("cosk:2", "uniform:1,0,1", 16, 16);
  BiasFamily family(0.04, 7);
  checkMethods(family, cosk,
               {Method::Equal, Method::Envmap, Method::Brdf, Method::Heuristic, Method::SigmaSqrtC, Method::Linear,
                Method::Exact},
               32, seed, closedForm(1, 0, 1, 2), "cosk:2");
  checkFamily(family);
  // f/p = L ρd = 1 for every BRDF sample: every pixel is 1 up to float rounding.
  Scene constant = smallScene("constant", "uniform:1,0,1", 16, 16);
  Rendering r = renderWith(constant, Method::Brdf, 32, 4100);
  CHECK(badValues(r, 2) == 0);
  float worst = 0;
  for (float v : r.image.rgb) worst = std::max(worst, std::abs(v - 1.0f));
  CHECK(worst < 1e-5f);
}

// ---------------------------------------------------------------------------------
// Envmaps
// ---------------------------------------------------------------------------------

TEST_CASE("rooitou_park, 69 % of the power in 0.1 % of the texels: techniques agree", "[stability]") {
  // BRDF-only sampling is left out: it finds the sun in ~1 sample of 10³, so its pixel
  // mean is heavy-tailed and its estimated standard error too small for a z-test. The
  // adaptive methods must not fall into that: the defensive floor keeps every
  // technique at one sample per stage (flooredPixels).
  Scene scene = smallScene("rooitou_park", "uniform:0.5,0.5,50", 32, 32);
  BiasFamily family(0.07, 5);  // each method against envmap
  checkMethods(family, scene,
               {Method::Envmap, Method::Equal, Method::Heuristic, Method::SigmaSqrtC, Method::Linear, Method::Exact},
               64, 5000, NAN, "rooitou_park", {}, {Method::Envmap, Method::Equal, Method::Exact});
  checkFamily(family);
}

TEST_CASE("a synthetic sun 1e6 times the sky: techniques agree", "[stability]") {
  BiasFamily family(0.05, 2 * 3);  // each method against envmap
  for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
    Scene scene = smallScene("sun:30,90,2,1e6", "uniform:0.5,0.5,20", 32, 32, false, s);
    checkMethods(family, scene, {Method::Envmap, Method::Equal, Method::Heuristic, Method::Linear}, 64,
                 s == EnvmapSampler::Cdf ? 5100 : 5200, NAN, fmt::format("sun 1e6 cdf {}", s == EnvmapSampler::Cdf), {},
                 {Method::Envmap, Method::Equal, Method::Heuristic});
  }
  checkFamily(family);
}

TEST_CASE("an all-black map gives exact zeros, the uniform fallback and no-signal fallbacks", "[stability]") {
  for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
    Scene scene = smallScene("constant:0", "uniform:0.5,0.5,20", 16, 16, true, s);
    CHECK(scene.tables.uniformFallback);
    for (Method m : {Method::Equal, Method::Envmap, Method::Brdf, Method::Heuristic, Method::SigmaSqrtC, Method::Linear,
                     Method::Exact, Method::Oracle}) {
      Rendering r = renderWith(scene, m, 30, 6000);
      INFO(methodName(m));
      CHECK(badValues(r, 3) == 0);
      CHECK(std::all_of(r.image.rgb.begin(), r.image.rgb.end(), [](float v) { return v == 0.0f; }));
      if (methodTraits(m).split == Split::Staged) CHECK(r.fallbackPixels == size_t(scene.pixelCount()));
      CHECK(r.flooredPixels == 0);  // the fallback's equal weights give every technique its share
    }
  }
}

TEST_CASE("a cost ratio of 1:1e8 either way floors every pixel of the rules that weigh by cost", "[stability]") {
  // Both techniques have variance in every pixel (a glossy BRDF under cos θ): σ/√c and
  // [HS14]'s heuristic give the dear technique about 1e-4 of a stage's 30-odd samples,
  // which rounds to 0, and the floor raises it to one sample in every pixel. No pixel
  // falls back: every one has signal.
  Scene scene = smallScene("cosk:1", "uniform:0.5,0.5,20", 16, 16);
  uint64_t seed = 6500;
  for (Method m : {Method::Heuristic, Method::SigmaSqrtC})
    for (const std::vector<double>& costs : {std::vector<double>{1, 1e8}, {1e8, 1}}) {
      Rendering r = renderWith(scene, m, 60, ++seed, costs);
      INFO(fmt::format("{} costs {}:{}", methodName(m), costs[0], costs[1]));
      CHECK(badValues(r, 2) == 0);
      CHECK(r.fallbackPixels == 0);
      CHECK(r.flooredPixels == size_t(scene.pixelCount()));
    }
}

TEST_CASE("a single bright texel: unbiased against its closed form", "[stability]") {
  // 64×32 map, texel (col 10, row 5) of radiance 1e4, the rest black. Pure diffuse at
  // normal view: (L/π) Δφ (sin²θ1 − sin²θ0)/2.
  const int W = 64, H = 32, col = 10, row = 5;
  const double L = 1e4;
  std::vector<float> rgb(size_t(3) * W * H, 0.0f);
  for (int c = 0; c < 3; ++c) rgb[3 * (size_t(row) * W + col) + c] = float(L);
  std::string path = writeMap("single-texel", W, H, rgb);
  const double pi = kPi;
  const double t0 = pi * row / H, t1 = pi * (row + 1) / H;
  const double expected = L / pi * (2 * pi / W) * (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0)) / 2;
  // BRDF sampling finds the texel in about one sample of 600: its tests detect a bias of
  // 70 %, the others' 0.2 %. The two families share the Šidák bound of all 10 tests.
  BiasFamily family(0.002, 2 * 5), brdfAlone(0.7, 2 * 5);
  for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
    Scene scene = smallScene(path, "uniform:1,0,1", 32, 32, false, s);
    CHECK_FALSE(scene.tables.uniformFallback);
    const uint64_t seed = s == EnvmapSampler::Cdf ? 7000 : 7100;
    const std::string what = fmt::format("texel cdf {}", s == EnvmapSampler::Cdf);
    checkMethods(family, scene, {Method::Envmap, Method::Equal, Method::Heuristic, Method::Linear}, 64, seed, expected,
                 what, {}, {Method::Envmap, Method::Equal});
    checkMethods(brdfAlone, scene, {Method::Brdf}, 64, seed + 4, expected, what);
  }
  std::remove(path.c_str());
  checkFamily(family);
  checkFamily(brdfAlone);
}

TEST_CASE("a map black on the upper hemisphere: the true value 0 is estimated as exactly 0", "[stability]") {
  const int W = 64, H = 32;
  std::vector<float> rgb(size_t(3) * W * H, 0.0f);
  for (size_t i = size_t(3) * W * (H / 2); i < rgb.size(); ++i) rgb[i] = 5.0f;
  std::string path = writeMap("lower-half", W, H, rgb);
  Scene scene = smallScene(path, "uniform:0.5,0.5,10", 16, 16, false, EnvmapSampler::Alias, 60.0);
  RgbImage zero;
  zero.width = zero.height = 16;
  zero.rgb.assign(size_t(3) * 16 * 16, 0.0f);
  for (Method m : {Method::Equal, Method::Envmap, Method::Brdf, Method::Heuristic, Method::SigmaSqrtC, Method::Linear,
                   Method::Exact}) {
    Rendering r = renderWith(scene, m, 30, 8000);
    INFO(methodName(m));
    CHECK(badValues(r, 2) == 0);
    double maxAbs = 0;
    for (float v : r.image.rgb) maxAbs = std::max(maxAbs, double(std::abs(v)));
    CHECK(maxAbs == 0.0);
    // Relative errors stay defined where the true value is 0.
    CHECK(std::isfinite(relativeMse(r.image, zero)));
    CHECK(std::isfinite(rmse(r.image, zero)));
    if (isAdaptive(m)) CHECK(r.fallbackPixels == size_t(scene.pixelCount()));
  }
  std::remove(path.c_str());
}

TEST_CASE("1x1 and 2x1 maps: unbiased against the constant's closed form", "[stability]") {
  // Normal view: the lobes are symmetric in φ, so the value is the mean radiance ×
  // (ρd + ρs) ([HS14] eq. 6.17 with K = 0 on the sphere's upper half).
  std::string one = writeMap("1x1", 1, 1, {2, 2, 2});
  std::string two = writeMap("2x1", 2, 1, {1, 1, 1, 3, 3, 3});
  uint64_t seed = 9000;
  // Envmap sampling alone, of a glossy lobe, sets the bound.
  BiasFamily family(0.08, 2 * 2 * 5);
  for (const std::string& path : {one, two}) {
    for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
      Scene scene = smallScene(path, "uniform:0.5,0.4,10", 16, 16, false, s);
      checkMethods(family, scene, {Method::Envmap, Method::Equal, Method::Brdf, Method::Heuristic, Method::Linear}, 32,
                   seed += 10, 2.0 * 0.9, fmt::format("{} cdf {}", path, s == EnvmapSampler::Cdf), {},
                   {Method::Envmap, Method::Equal});
    }
  }
  std::remove(one.c_str());
  std::remove(two.c_str());
  checkFamily(family);
}

TEST_CASE("a map past 2^24 texels: tables sum to 1 in double and sampling stays unbiased", "[stability][large]") {
  // constant:1 at width 8192: 3.4e7 texels, past the 2^24 that a float counts exactly
  // and a 24-bit uniform resolves. The table precision is checked on the host; a few
  // pixels sample it against the closed form ρd + ρs. Both samplers: the alias table's
  // 32-bit bucket index and the CDFs' 24-bit uniforms over 8192 columns. Exhaustive test
  // size: 16384 × 8192 (1.3e8 texels, 4× the time); small (the sanitizers): 4096 × 2048,
  // through the same code.
  const int width = smallTestSize() ? 4096 : exhaustiveTestSize() ? 16384 : 8192;
  BiasFamily family(0.03, 2);
  for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
    auto start = std::chrono::steady_clock::now();
    SceneOptions o;
    o.envmap = "constant";
    o.grid = "uniform:0.5,0.5,10";
    o.width = 8;
    o.height = 8;
    o.proceduralWidth = width;
    o.sampler = sampler;
    Scene scene = makeScene(o);
    REQUIRE(scene.tables.width == width);
    REQUIRE(scene.tables.height == width / 2);
    double total = 0;
    size_t bad = 0;
    const size_t texels = size_t(width) * (width / 2);
    for (size_t t = 0; t < texels; ++t) {
      double p = scene.tables.texels[4 * t + 3];
      total += p;
      bad += !(std::isfinite(p) && p > 0);
    }
    const bool cdf = sampler == EnvmapSampler::Cdf;
    INFO(fmt::format("cdf {}: Σ p − 1 = {}", cdf, total - 1));
    CHECK(bad == 0);
    // Float probabilities of 1.3e8 texels, summed in double: 1 to ~1e-7.
    CHECK(std::abs(total - 1) < 1e-6);
    double mem = 4.0 * (scene.tables.texels.size() + scene.tables.aliasTable.size() + scene.tables.cdfTable.size() +
                        scene.envmap.image.rgb.size());
    INFO(fmt::format("host memory of map and tables {:.2f} GiB", mem / (1 << 30)));
    // Per texel at most: RGB 12 B, texel + probability 16 B, alias 8 B or CDF 4 B.
    CHECK(mem <= 36.0 * texels + 1e6);
    Rendering r = renderWith(scene, Method::Equal, 256, cdf ? 9100 : 9200);
    CHECK(badValues(r, 2) == 0);
    addEstimate(family, fmt::format("cdf {}", cdf), imageMean(r), 1.0);
    INFO(fmt::format("seconds {}", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
  }
  checkFamily(family);
}

// ---------------------------------------------------------------------------------
// Allocations
// ---------------------------------------------------------------------------------

TEST_CASE("[SS23] example 6: the optimum on the simplex boundary, alpha_1 = 0", "[stability]") {
  Example1D example = paperExample("003-6");
  OptimalMixture best =
      minimiseInefficiency(example, VarianceModel::MultiSample, std::vector<double>(example.costs().size(), 1.0));
  INFO(fmt::format("alpha {}", fmt::join(best.alpha, ", ")));
  CHECK(onSimplex(best.alpha));
  CHECK(best.alpha[0] < 1e-6);
  CHECK(std::isfinite(best.inefficiency));
  StudyConfig config;
  config.runs = 40;
  for (const RuleOutcome& o : runAllocationStudy(example, config)) {
    INFO(allocationRuleName(o.rule));
    CHECK(onSimplex(o.meanAlpha));
    CHECK(std::isfinite(o.inefficiency.mean));
    CHECK(std::isfinite(o.inefficiency.p90));
  }
}

TEST_CASE("zero-variance mixtures ([SS23] example 2, [SHS16] example 4) without 0/0", "[stability]") {
  for (const char* id : {"003-2", "002-4"}) {
    Example1D example = paperExample(id);
    StudyConfig config;
    config.runs = 40;
    std::vector<RuleOutcome> outcomes = runAllocationStudy(example, config);
    // The scale of λ = ∫ f²/p_α ≥ I² at a zero-variance mixture, times the costs.
    const double cost = *std::max_element(example.costs().begin(), example.costs().end());
    const double scale = cost * example.integral() * example.integral();
    for (const RuleOutcome& o : outcomes) {
      INFO(fmt::format("{} {}: inefficiency {} fallback runs {}", id, allocationRuleName(o.rule), o.inefficiency.mean,
                       o.fallbackRuns));
      CHECK(onSimplex(o.meanAlpha));
      CHECK(std::isfinite(o.inefficiency.mean));
      CHECK(std::isfinite(o.inefficiency.p90));
      // The exact variance λ − Σ α_k m_k² of a zero-variance mixture is 0 up to the
      // double round-off of that difference (~1e-16 λ), never a real negative number.
      CHECK(o.inefficiency.mean >= -1e-12 * scale);
      if (o.rule == AllocationRule::LinearDropMostNegative || o.rule == AllocationRule::LinearMinSampleVariance)
        CHECK(std::abs(o.inefficiency.mean) <= 1e-12 * scale);  // [SS23]: the linear heuristic finds the mixture
    }
  }
}

TEST_CASE("a pilot of 2 samples per technique whose values are all equal", "[stability]") {
  // Constant map, pure diffuse: every BRDF sample has f/p = 1 (estimated variance 0).
  // spp 20 with a 20 % pilot is 2 samples per technique.
  Scene scene = smallScene("constant", "uniform:1,0,1", 16, 16);
  for (Method m : kAdaptive) REQUIRE(stageSizes(0.2, 4, 20, 2, m).front() == 4);
  BiasFamily family(0.04, int(kAdaptive.size()));
  for (Method m : kAdaptive) {
    Rendering r = renderWith(scene, m, 20, 10000);
    addEstimate(family, methodName(m), imageMean(r), 1.0);
    INFO(fmt::format("{}: fallback {}", methodName(m), r.fallbackPixels));
    CHECK(badValues(r, 2) == 0);
    if (m == Method::Heuristic) CHECK(r.fallbackPixels == size_t(scene.pixelCount()));  // V_brdf = 0
  }
  checkFamily(family);
}

TEST_CASE("a technique whose samples are all zero: flagged, weight 0, unbiased", "[stability]") {
  // A single bright texel lit pure-diffuse: the BRDF technique's pilot samples almost
  // always miss it (f = 0); the envmap technique's never do. The per-technique rules
  // flag the silent technique and give it weight 0; exact's rule (b) estimates V(α)
  // from every sample (kernels/gridsearch.h) and needs no flag to move α to the envmap.
  const int W = 64, H = 32;
  std::vector<float> rgb(size_t(3) * W * H, 0.0f);
  for (int c = 0; c < 3; ++c) rgb[3 * (size_t(5) * W + 10) + c] = 1e4f;
  std::string path = writeMap("silent", W, H, rgb);
  Scene scene = smallScene(path, "uniform:1,0,1", 16, 16);
  const double pi = kPi, t0 = pi * 5 / H, t1 = pi * 6 / H;
  const double expected = 1e4 / pi * (2 * pi / W) * (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0)) / 2;
  BiasFamily family(0.005, int(kAdaptive.size()));
  for (Method m : kAdaptive) {
    Rendering r = renderWith(scene, m, 40, 11000);
    addEstimate(family, methodName(m), imageMean(r), expected);
    INFO(fmt::format("{}: fallback {}", methodName(m), r.fallbackPixels));
    CHECK(badValues(r, 2) == 0);
    if (m != Method::Exact) {
      CHECK(r.fallbackPixels > size_t(scene.pixelCount()) / 2);
      continue;
    }
    double brdfShare = 0;
    for (int p = 0; p < scene.pixelCount(); ++p) brdfShare += r.alpha[size_t(p) * 2 + 1] / scene.pixelCount();
    CHECK(brdfShare < 0.1);
  }
  std::remove(path.c_str());
  checkFamily(family);
}

TEST_CASE("a cost ratio of 1:1000 either way stays unbiased and on the simplex", "[stability]") {
  Scene scene = smallScene("cosk:1", "uniform:0.5,0.5,20", 32, 32);
  uint64_t seed = 12000;
  BiasFamily family(0.05, 2 * int(kAdaptive.size()));
  for (std::vector<double> costs : {std::vector<double>{1, 1000}, std::vector<double>{1000, 1}}) {
    checkMethods(family, scene, kAdaptive, 60, seed += 10, closedForm(0.5, 0.5, 20, 1),
                 fmt::format("costs {}:{}", costs[0], costs[1]), costs);
  }
  checkFamily(family);
}

TEST_CASE("pixels whose true value is 0 (a black BRDF): exact zeros, relative errors stay defined", "[stability]") {
  // ρd = ρs = 0 under the sun map: every pixel is exactly 0 (for a map black on the
  // upper hemisphere, see that case).
  Scene scene = smallScene("rooitou_park", "uniform:0,0,10", 16, 16);
  RgbImage zero;
  zero.width = zero.height = 16;
  zero.rgb.assign(size_t(3) * 16 * 16, 0.0f);
  for (Method m : {Method::Equal, Method::Heuristic, Method::SigmaSqrtC, Method::Linear, Method::Exact}) {
    Rendering r = renderWith(scene, m, 30, 13000);
    INFO(methodName(m));
    CHECK(badValues(r, 2) == 0);
    CHECK(std::isfinite(relativeMse(r.image, zero)));
    CHECK(std::isfinite(relativeMse(zero, r.image)));
    CHECK(std::all_of(r.image.rgb.begin(), r.image.rgb.end(), [](float v) { return v == 0.0f; }));
    if (isAdaptive(m)) CHECK(r.fallbackPixels == size_t(scene.pixelCount()));
  }
}

// ---------------------------------------------------------------------------------
// Precision
// ---------------------------------------------------------------------------------

TEST_CASE("1e7 samples per pixel: the accumulated estimate keeps double precision", "[stability][precision]") {
  // One work-item of the kernel: float sums would drift by ~1e-4 relative after 1e7
  // terms, far beyond the standard error of ~1e-4/√... of this low-variance integrand.
  Scene scene = smallScene("cosk:1", "uniform:0.5,0.5,5", 1, 1);
  const double expected = closedForm(0.5, 0.5, 5, 1);
  Rendering r = renderWith(scene, Method::Equal, 10000000, 14000, {}, 1);
  CHECK(badValues(r, 2) == 0);
  BiasFamily family(0.001, 1);
  family.add("one pixel", luminance(r.image.rgb[0], r.image.rgb[1], r.image.rgb[2]), expected,
             std::sqrt(r.variance[0]));
  checkFamily(family);
}

TEST_CASE("f^2/p^2 near and beyond the float range: finite, unbiased", "[stability][precision]") {
  // Radiance 1e19 and 1e30: w = f/p ~ R, w² ~ 1e38 (float's edge) and 1e60 (beyond).
  uint64_t seed = 15000;
  BiasFamily family(0.04, 2 * 5);
  for (double R : {1e19, 1e30}) {
    Scene scene = smallScene(fmt::format("constant:{}", R), "uniform:0.5,0.5,10", 16, 16);
    checkMethods(family, scene, {Method::Equal, Method::Heuristic, Method::SigmaSqrtC, Method::Linear, Method::Exact},
                 32, seed += 10, R, fmt::format("R {}", R));
  }
  checkFamily(family);
}

// ---------------------------------------------------------------------------------
// Reports
// ---------------------------------------------------------------------------------

namespace {

// Every number in the report is finite: nlohmann::json writes NaN and ±∞ as null.
size_t nonFiniteEntries(const nlohmann::json& j) {
  if (j.is_null()) return 1;
  if (j.is_number_float()) return std::isfinite(j.get<double>()) ? 0 : 1;
  size_t bad = 0;
  if (j.is_structured())
    for (const auto& item : j) bad += nonFiniteEntries(item);
  return bad;
}

}  // namespace

TEST_CASE("reports of hard scenes hold only finite numbers and count the defensive rules", "[stability][cli]") {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / fmt::format("misalloc-stability-cli-{}", ::getpid());
  fs::create_directories(dir);
  struct Case {
    std::string scene;
    bool black;
  };
  const Case cases[] = {{"--envmap constant:0 --grid uniform:0.5,0.5,10", true},
                        {"--envmap sun:30,90,0.5,1e6 --grid general:0.2,0.8,1,100000", false}};
  for (const Case& c : cases) {
    for (const char* method : {"heuristic", "linear"}) {
      fs::path out = dir / "r.exr", report = dir / "r.json";
      std::string command = fmt::format(
          "{} render {} --size 8x8 --spp 20 --method {} --reference-spp 64 --cache-dir {} --out {} "
          "--report {} 2>&1",
          misallocBinary(), c.scene, method, (dir / "cache").string(), out.string(), report.string());
      FILE* pipe = popen(command.c_str(), "r");
      REQUIRE(pipe != nullptr);
      std::string output;
      char buffer[4096];
      while (size_t n = fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, n);
      int status = pclose(pipe);
      INFO(c.scene << " " << method << "\n" << output);
      REQUIRE(WIFEXITED(status));
      REQUIRE(WEXITSTATUS(status) == 0);
      nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
      INFO(j.dump(2));
      CHECK(nonFiniteEntries(j) == 0);
      if (c.black) {
        CHECK(j["scene"]["envmap_uniform_fallback"] == true);
        CHECK(j["allocation"]["fallback_pixels"] == 64);  // no signal anywhere
        CHECK(j["allocation"]["floored_pixels"] == 0);    // the fallback's equal weights
        CHECK(output.find("falls back to uniform") != std::string::npos);
      }
      RgbImage image = readExr(out.string());
      CHECK(std::all_of(image.rgb.begin(), image.rgb.end(), [](float v) { return std::isfinite(v); }));
    }
  }
  fs::remove_all(dir);
}
