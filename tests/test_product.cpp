// The product technique (kernels/product.h, host/distributions/ProductTables.h): the
// texels it draws follow the pdf every MIS weight reads, that pdf integrates to 1 and is
// positive wherever the map is lit, and estimators that use it are unbiased against
// [HS14] eq. 6.17 on both samplers and every envmap pdf.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "BiasCheck.h"
#include "CliRunner.h"
#include "Constants.h"
#include "Error.h"
#include "KernelCode.h"
#include "PictureChecks.h"
#include "SafetyWorkspace.h"
#include "SceneFixtures.h"
#include "Statistics.h"
#include "TestDevice.h"
#include "TestSize.h"
#include "render/Render.h"
#include "report/AlphaMap.h"
#include "sampling/HostSampler.h"
#include "sampling/KernelViews.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

constexpr double kFloatRounding = 0x1p-24;

Scene productScene(const std::string& envmap, const std::string& grid, int w, int h, double viewTheta,
                   const std::string& pdf = "plain", EnvmapSampler sampler = EnvmapSampler::Alias) {
  return smallScene(envmap, grid, w, h, false, sampler, viewTheta, pdf, true);
}

// A sphere under a sun, 16 × 16 pixels, with the product technique and `pdf`.
SceneOptions productSphere(const std::string& pdf) {
  SceneOptions o;
  o.envmap = "sun";
  o.proceduralWidth = 64;
  o.shape = "sphere";
  o.width = o.height = 16;
  o.product = true;
  o.envmapPdf = parseEnvmapPdf(pdf);
  return o;
}

kern::PhongParams phongOf(const PhongParameters& p) {
  kern::PhongParams b;
  b.rhoD = p.rhoD;
  b.rhoS = p.rhoS;
  b.n = p.n;
  return b;
}

// Each texel's probability under pixel b's product: the block's ratio to the plain
// envmap's times the texel's plain probability.
std::vector<double> productTexelProbabilities(const Scene& scene, const kern::PhongParams& b) {
  const kern::EnvmapView env = makeEnvmapView(scene.tables, -1);
  const kern::ProductView view = makeProductView(scene.productTables);
  const kern::ProductMixture m = kern::productMixture(view, b);
  const int width = scene.tables.width, height = scene.tables.height, L = view.blockLog2;
  const float* plain = view.floats + view.tables + view.tables * kern::productBlocks(env, view);
  std::vector<double> p(std::size_t(width) * height);
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col) {
      const int block = (row >> L) * kern::productBlocksAcross(env, view) + (col >> L);
      const std::size_t t = std::size_t(row) * width + col;
      p[t] = double(kern::productRatio(env, view, m, block)) * plain[t];
    }
  return p;
}

}  // namespace

TEST_CASE("the product technique draws texels with the probabilities its pdf reads, which integrate to 1",
          "[product]") {
  // A real map, a small sun 10⁵ times the sky, and cos^K; a diffuse, a glossy, a
  // near-mirror and a black BRDF, seen along the normal and 60° off it. One χ² test per
  // case; a false alarm in any of them with probability 2 %.
  const std::vector<std::string> maps = {"venice_sunset", "sun:40,90,0.5,1e5", "cosk:3"};
  const std::vector<PhongParameters> brdfs = {{0.9f, 0.1f, 2}, {0.2f, 0.8f, 40}, {0.0f, 1.0f, 5000}, {0, 0, 10}};
  const std::vector<double> views = {0, 60};
  const double level = sidakLevel(0.02, int(maps.size() * brdfs.size() * views.size()));
  for (const std::string& map : maps)
    for (double view : views) {
      // The grid holds every BRDF, so that every one has its exponent's table.
      const Scene scene = productScene(map, "seed000", 8, 8, view);
      Scene withBrdfs = scene;
      for (std::size_t i = 0; i < brdfs.size(); ++i) withBrdfs.grid.pixels[i] = brdfs[i];
      // The scene keeps no copy of the map's image with the plain pdf: read it again.
      const Envmap envmap = makeEnvmap(resolveEnvmapSpec(map), scene.options.proceduralWidth);
      withBrdfs.productTables = buildProductTables(envmap, withBrdfs.grid, flatMirror(scene.geometry, "--product"));
      withBrdfs.productTables.plainTexels = scene.productTables.plainTexels;
      const kern::EnvmapView env = makeEnvmapView(withBrdfs.tables, -1);
      const kern::ProductView product = makeProductView(withBrdfs.productTables);
      REQUIRE(product.tables >= 3);
      for (std::size_t i = 0; i < brdfs.size(); ++i) {
        const kern::PhongParams b = phongOf(brdfs[i]);
        INFO(fmt::format("{} view {} BRDF {},{},{}", map, view, b.rhoD, b.rhoS, b.n));
        const kern::ProductMixture mixture = kern::productMixture(product, b);
        const std::vector<double> p = productTexelProbabilities(withBrdfs, b);
        double sum = 0;
        for (double v : p) sum += v;
        // Three tables' block probabilities and a texel's, each rounded to float once, and
        // the mixture's products and sums: each term within 16 roundings of its own value.
        CHECK(std::abs(sum - 1) <= 16 * kFloatRounding);
        // Positive wherever the plain envmap pdf is: unbiased wherever the map is lit.
        std::size_t uncovered = 0;
        for (std::size_t t = 0; t < p.size(); ++t) uncovered += withBrdfs.tables.texels[4 * t + 3] > 0 && !(p[t] > 0);
        CHECK(uncovered == 0);

        // The kernels' sampler with its own random numbers: draw and mixture choice.
        const uint64_t samples = 200000;
        std::vector<uint64_t> counts(p.size(), 0);
        for (uint64_t s = 0; s < samples; ++s) {
          const kern::MaRandom4 rnd = kern::philoxDraw(0x9d, uint32_t(i), 0, 2, uint32_t(s));
          const float u = kern::uniformFloat(kern::philoxDrawPart(0x9d, uint32_t(i), 0, 2, uint32_t(s), 1).v[0]);
          ++counts[kern::sampleProduct(env, product, mixture, rnd, u).texel];
        }
        uint64_t zeroDraws = 0;
        for (std::size_t t = 0; t < p.size(); ++t) zeroDraws += p[t] == 0 ? counts[t] : 0;
        CHECK(zeroDraws == 0);
        const ChiSquare test = chiSquare(counts, p, samples);
        INFO("chi^2 = " << test.statistic << " with " << test.degreesOfFreedom << " degrees of freedom");
        CHECK(test.pValue() > level);

        // With the plain pdf and the alias sampler, the product scales the envmap's own
        // pdf (ProductView::plainTexels): the texels' plain probabilities are its own.
        REQUIRE(withBrdfs.productTables.plainTexels);
        const float* plain = product.floats + product.tables + product.tables * kern::productBlocks(env, product);
        std::size_t differ = 0;
        for (std::size_t t = 0; t < p.size(); ++t) differ += plain[t] != withBrdfs.tables.texels[4 * t + 3];
        CHECK(differ == 0);

        // The solid-angle pdf a BRDF-sampled direction reads, by the midpoint rule, on
        // the path that reads the texel's plain probability, as with the other pdfs.
        kern::ProductView ownTexels = product;
        ownTexels.plainTexels = 0;
        const int k = p.size() > 100000 ? 1 : 4;
        const int nu = k * env.width, nv = k * env.height;
        double integral = 0;
        std::size_t pathsDiffer = 0;
        for (int j = 0; j < nv; ++j) {
          const double v = (j + 0.5) / nv;
          const double rowWeight = 2 * kPi * kPi * std::sin(kPi * v) / (double(nu) * nv);
          for (int c = 0; c < nu; ++c) {
            const kern::MaVec3 w = kern::latLongDirection(float((c + 0.5) / nu), float(v));
            const int t = kern::texelOfDirection(env, w);
            const float sinTheta = std::sqrt(w.x * w.x + w.y * w.y);
            const float pdf = kern::productPdf(env, ownTexels, mixture, t, 0.0f, sinTheta);
            pathsDiffer +=
                pdf != kern::productPdf(env, product, mixture, t, kern::envmapTexelHit(env, t, w).pdf, sinTheta);
            integral += pdf * rowWeight;
          }
        }
        // And envmapPdfOfTexel's float arithmetic, with sin θ of a float direction.
        CHECK(std::abs(integral - 1) <= 64 * kFloatRounding);
        CHECK(pathsDiffer == 0);  // scaling the envmap's pdf is reading the texel's own
      }
    }
}

TEST_CASE("a pixel's product mixture follows its BRDF's lobes", "[product]") {
  const Scene scene = productScene("venice_sunset", "seed000", 8, 8, 30);
  const kern::ProductView product = makeProductView(scene.productTables);
  // A diffuse BRDF takes no specular table, a pure lobe no diffuse one; the plain
  // envmap keeps its share; a black BRDF takes the plain envmap alone.
  kern::ProductMixture diffuse = kern::productMixture(product, phongOf({1, 0, 10}));
  CHECK(diffuse.specular == 0);
  CHECK(diffuse.diffuse == Approx(1 - MA_PRODUCT_PLAIN_SHARE).epsilon(1e-6));
  kern::ProductMixture glossy = kern::productMixture(product, phongOf({0, 1, 10}));
  CHECK(glossy.diffuse == 0);
  CHECK(glossy.specular == Approx(1 - MA_PRODUCT_PLAIN_SHARE).epsilon(1e-6));
  kern::ProductMixture black = kern::productMixture(product, phongOf({0, 0, 10}));
  CHECK(black.diffuse == 0);
  CHECK(black.specular == 0);
  // Every exponent finds the table of its own bin when the grid has it.
  for (const PhongParameters& p : scene.grid.pixels) {
    const int bin = kern::productExponentBin(p.n);
    CHECK(int(product.words[bin]) >= MA_PRODUCT_TABLE_DIFFUSE + 1);
    CHECK(int(product.words[bin]) < product.tables);
  }
}

TEST_CASE("estimators with the product technique are unbiased against [HS14] eq. 6.17", "[unbiased][product]") {
  struct Case {
    double rhoD, n, K;
  };
  const Case cases[] = {{0.5, 5, 1}, {0.2, 50, 3}, {0.05, 1000, 0.5}, {0.7, 0.1, 6}};
  const std::vector<int> picked = smallTestSize() ? std::vector<int>{0, 2} : std::vector<int>{0, 1, 2, 3};
  BiasFamily family(0.02);
  for (int i : picked) {
    const Case& c = cases[i];
    uint64_t seed = 900 + uint64_t(64 * i);
    const double expected = closedForm(c.rhoD, 1 - c.rhoD, c.n, c.K);
    for (const std::string pdf : {"plain", "compensated", "optimal", "optimal-pixel"})
      for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
        // The other pdfs on two BRDFs, multi-sample: the cases the sweep ran when each K
        // was a PoCL kernel of its own, under the same seeds. The optimal pdf per pixel,
        // whose product comes from its cells, with one-sample MIS too; it draws its cells
        // by its own CDF, whatever the sampler.
        const bool plain = pdf == "plain", pixelCells = pdf == "optimal-pixel";
        if (!plain && i % 2 == 1) continue;
        if (pixelCells && s == EnvmapSampler::Cdf) continue;
        const Scene scene = productScene(fmt::format("cosk:{}", c.K),
                                         fmt::format("uniform:{},{},{}", c.rhoD, 1 - c.rhoD, c.n), 32, 32, 0, pdf, s);
        REQUIRE(scene.techniqueCount() == 3);
        REQUIRE(scene.productTables.pixelCells == pixelCells);
        // The product alone, the three techniques in equal counts, and one-sample MIS.
        struct Run {
          const char* name;
          bool productAlone;
          Estimator estimator;
        };
        for (const Run& run :
             {Run{"product alone", true, Estimator::MultiSample}, Run{"equal", false, Estimator::MultiSample},
              Run{"equal one-sample", false, Estimator::OneSample}}) {
          if (!plain && !pixelCells && run.estimator == Estimator::OneSample) continue;
          auto renderMean = [&](int spp, uint64_t sd) {
            StagePlan plan = singleStagePlan(scene, Method::Equal, spp);
            if (run.productAlone)
              for (int p = 0; p < scene.pixelCount(); ++p) {
                plan.counts[3 * p] = plan.counts[3 * p + 1] = 0;
                plan.counts[3 * p + 2] = spp;
              }
            return pixelMean(sweepSampler(scene, {run.estimator, 0, 0})->run(plan, sd).rgb);
          };
          addSized(family,
                   fmt::format("rhoD {} n {} K {} pdf {} cdf {} {}", c.rhoD, c.n, c.K, pdf, s == EnvmapSampler::Cdf,
                               run.name),
                   expected, 48, 48, ++seed, renderMean);
        }
      }
  }
  checkFamily(family);
}

TEST_CASE("the product technique with split lobes is refused: 4 techniques", "[product][bad-input]") {
  SceneOptions o;
  o.envmap = "constant";
  o.grid = "uniform:0.5,0.5,10";
  o.width = o.height = 4;
  o.splitBrdf = o.product = true;
  o.envmapPdf = parseEnvmapPdf("plain");
  CHECK_THROWS_WITH(makeScene(o), Catch::Matchers::Contains("--product with --split-brdf: not implemented"));
}

TEST_CASE(
    "on per-pixel normals and views the product comes from the optimal pdf per pixel's cells, and its tables are "
    "refused",
    "[product][geometry][bad-input]") {
  CHECK_THROWS_WITH(makeScene(productSphere("plain")),
                    Catch::Matchers::Contains("--product with --envmap-pdf plain and per-pixel normals or views: not "
                                              "implemented"));
  const Scene scene = makeScene(productSphere("optimal-pixel"));
  CHECK(scene.techniqueNames() == std::vector<std::string>{"envmap", "brdf", "product"});
  CHECK(scene.productTables.pixelCells);
  CHECK(scene.productTables.tables == 0);  // no table binned over BRDFs or geometry
  CHECK(scene.tables.pixelCells > 0);
}

TEST_CASE("BRDF sampling alone gives the product technique no samples: technique 2 is the product, not a lobe",
          "[product][roles]") {
  const Scene product =
      smallScene("constant", "uniform:0.5,0.5,10", 4, 4, false, EnvmapSampler::Alias, 0, "plain", true);
  CHECK(product.techniqueNames() == std::vector<std::string>{"envmap", "brdf", "product"});
  CHECK(methodCounts(product, Method::Brdf, 16, 0) == std::vector<int>{0, 16, 0});
  // With the lobes split, brdf shares its samples between them by their albedos.
  const Scene split = smallScene("constant", "uniform:0.5,0.5,10", 4, 4, true);
  CHECK(split.techniqueNames() == std::vector<std::string>{"envmap", "diffuse", "specular"});
  CHECK(methodCounts(split, Method::Brdf, 16, 0) == std::vector<int>{0, 8, 8});
}

TEST_CASE("compare --product runs the methods that sample it, one scene with every pdf, and refuses the others",
          "[product][compare][cli][bad-input]") {
  // On the C++ sampler: what is checked is which runs compare makes and how it lays them
  // out, and PoCL would compile a kernel variant per method (48 s of CI).
  TempDir dir("compare_product");
  const std::string args = fmt::format(
      "compare --envmap sun --size 8x8 --product --budgets 16 --repeats 1 --envmap-pdfs plain --reference-spp 64 "
      "--cost 1,1,2 --device host --cache-dir {} ",
      (dir.path / "cache").string());
  auto all = runMisalloc(args + "--out-dir " + (dir.path / "all").string());
  INFO(all.output);
  REQUIRE(all.exitCode == 0);
  std::set<std::string> methods;
  const auto runs = nlohmann::json::parse(readText(dir.path / "all" / "runs.json"));
  for (const auto& run : runs["runs"]) methods.insert(run["method"].get<std::string>());
  CHECK(methods == std::set<std::string>{"equal", "heuristic", "sigma-sqrt-c", "linear", "exact", "oracle"});
  // With the default pdfs, plain and optimal: one scene, in one plot and one column of the
  // pdfs' table, as without --product.
  auto pdfs = runMisalloc(fmt::format(
      "compare --envmap sun --size 8x8 --product --methods equal,exact --budgets 16,32 --repeats 1 --reference-spp 64 "
      "--cost 1,1,2 --device host --cache-dir {} --out-dir {}",
      (dir.path / "cache").string(), (dir.path / "pdfs").string()));
  INFO(pdfs.output);
  REQUIRE(pdfs.exitCode == 0);
  CHECK(fs::exists(dir.path / "pdfs" / "plot_sun-product.svg"));
  CHECK_FALSE(fs::exists(dir.path / "pdfs" / "plot_sun-product-optimal.svg"));
  const std::string table = readText(dir.path / "pdfs" / "envmap_pdfs.md");
  CHECK(table.find("| sun-product | geometric mean |") != std::string::npos);
  CHECK(table.find("—") == std::string::npos);  // every method with every pdf
  auto ris = runMisalloc(args + "--methods equal,ris --out-dir " + (dir.path / "ris").string());
  CHECK(ris.exitCode == 2);
  CHECK(ris.output.find("--product with --method ris") != std::string::npos);
  CHECK_FALSE(fs::exists(dir.path / "ris"));
}

TEST_CASE("compare --product on per-pixel geometry runs the optimal pdf per pixel alone, and refuses the plain pdf",
          "[product][compare][cli][bad-input]") {
  TempDir dir("compare_product_cells");
  const std::string args = fmt::format(
      "compare --scene sphere --envmap sun --size 16x16 --product --methods equal,exact --budgets 16 --repeats 1 "
      "--reference-spp 64 --cost 1,1,2 --device host --cache-dir {} ",
      (dir.path / "cache").string());
  auto cells = runMisalloc(args + "--out-dir " + (dir.path / "cells").string());
  INFO(cells.output);
  REQUIRE(cells.exitCode == 0);
  const auto runs = nlohmann::json::parse(readText(dir.path / "cells" / "runs.json"));
  std::set<std::string> cases;
  for (const auto& run : runs["runs"]) cases.insert(run["case"].get<std::string>());
  CHECK(cases == std::set<std::string>{"sun-sphere-product-optimal-pixel"});
  auto plain = runMisalloc(args + "--envmap-pdfs plain,optimal-pixel --out-dir " + (dir.path / "plain").string());
  CHECK(plain.exitCode == 2);
  CHECK(plain.output.find("--product with --envmap-pdfs plain on per-pixel normals or views: not implemented") !=
        std::string::npos);
  CHECK_FALSE(fs::exists(dir.path / "plain"));
  auto render =
      runMisalloc(fmt::format("render --scene sphere --envmap sun --size 16x16 --product --envmap-pdf plain "
                              "--spp 8 --out {}",
                              (dir.path / "render.exr").string()));
  CHECK(render.exitCode == 2);
  CHECK(render.output.find("--product with --envmap-pdf plain and per-pixel normals or views") != std::string::npos);
  CHECK_FALSE(fs::exists(dir.path / "render.exr"));
}

TEST_CASE("the α map's picture shows the product technique's share in green", "[product][outputs]") {
  // [HS14] Fig. 5.5's colours, blue for envmap sampling and red for BRDF sampling, with
  // the product's share green: the product's samples are neither.
  const Scene scene = makeScene(productSphere("optimal-pixel"));
  AdaptiveOptions options;
  options.costs = {1, 1, 1};
  HostSampler sampler(scene,
                      samplerConfigFor(Method::Exact, Estimator::MultiSample, 64, options, scene.techniqueCount()));
  const Rendering r = render(sampler, Method::Exact, options, 64, 3);
  const std::vector<uint8_t> picture = decodePng(encodeAlphaMaps(scene, r).png).rgb;
  size_t misdrawn = 0, covered = 0, green = 0;
  for (size_t p = 0; p < size_t(scene.pixelCount()); ++p) {
    const uint8_t* rgb = picture.data() + 3 * p;
    const double envmap = r.alpha[3 * p], brdf = r.alpha[3 * p + 1], product = r.alpha[3 * p + 2];
    if (!scene.geometry.covered[p]) {
      misdrawn += rgb[0] + rgb[1] + rgb[2] != 0;
      continue;
    }
    ++covered;
    green += rgb[1] > 0;
    misdrawn += std::abs(rgb[0] - 255 * brdf) > 0.5 || std::abs(rgb[1] - 255 * product) > 0.5 ||
                std::abs(rgb[2] - 255 * envmap) > 0.5;
  }
  CHECK(covered > 0);
  CHECK(green == covered);  // the defensive floor gives every technique some samples
  CHECK(misdrawn == 0);
}

TEST_CASE("under a black map the product falls back with the optimal pdf per pixel, on per-pixel geometry too",
          "[product][geometry][finite]") {
  // The optimal pdf per pixel falls back to plain where nothing is lit, and has no cells
  // for the product to come from: its tables then hold the plain envmap's alone.
  SceneOptions o = productSphere("optimal-pixel");
  o.envmap = "constant:0";
  const Scene scene = makeScene(o);
  CHECK(scene.tables.pixelCells == 0);
  CHECK_FALSE(scene.productTables.pixelCells);
  CHECK(scene.productTables.tables > 0);
  for (Method method : {Method::Equal, Method::Exact}) {
    AdaptiveOptions options;
    options.costs = {1, 1, 1};
    HostSampler sampler(scene, samplerConfigFor(method, Estimator::MultiSample, 32, options, scene.techniqueCount()));
    const Rendering r = render(sampler, method, options, 32, 5);
    size_t nonZero = 0;
    for (float v : r.image.rgb) nonZero += v != 0.0f;
    CHECK(nonZero == 0);
  }
}
