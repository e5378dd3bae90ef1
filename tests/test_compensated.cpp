// The MIS-compensated envmap pdf ([Kar19] eq. 14): its tables, its fallback on a
// constant map, the refusal of envmap sampling alone, and the unbiasedness of every
// method with it against the closed form [HS14] eq. 6.17. The pdf ∝ max(0, L − 2(1−C)·L̄)
// is zero on most of a cos^K map, so these estimates rest on BRDF sampling there.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "BiasCheck.h"
#include "CliRunner.h"
#include "Error.h"
#include "RunRecords.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "TestSize.h"
#include "compare/EnvmapPdfComparison.h"
#include "compare/Suite.h"
#include "render/Reference.h"
#include "render/Render.h"
#include "render/RunChecks.h"
#include "report/Report.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

Scene compensatedScene(const std::string& envmap, const std::string& grid, const std::string& pdf,
                       EnvmapSampler sampler = EnvmapSampler::Alias, bool split = false, int size = 32) {
  SceneOptions o;
  o.envmap = envmap;
  o.grid = grid;
  o.width = o.height = size;
  o.splitBrdf = split;
  o.sampler = sampler;
  o.envmapPdf = parseEnvmapPdf(pdf);
  o.proceduralWidth = 128;
  return makeScene(o);
}

double luminanceOfTexel(const EnvmapTables& tables, size_t t) {
  return 0.2126 * tables.texels[4 * t] + 0.7152 * tables.texels[4 * t + 1] + 0.0722 * tables.texels[4 * t + 2];
}

Rendering renderWith(const Scene& scene, Method method, Estimator estimator, int spp, uint64_t seed) {
  AdaptiveOptions options;
  options.costs.assign(scene.techniqueCount(), 1.0);
  options.oracleSamples = 128;
  requireValidRun(scene.options, method, estimator, spp, options);
  const auto sampler = sweepSampler(scene, samplerConfigFor(method, estimator, spp, options, scene.techniqueCount()));
  return render(*sampler, method, options, spp, seed);
}

MeanAndError imageMean(const Scene& scene, Method method, Estimator estimator, int spp, uint64_t seed) {
  const Rendering r = renderWith(scene, method, estimator, spp, seed);
  return pixelMean(std::vector<double>(r.image.rgb.begin(), r.image.rgb.end()));
}

// Every method that samples the BRDF, with each estimator it takes.
const std::vector<std::pair<Method, Estimator>> kMethodsWithBrdfSampling = {
    {Method::Brdf, Estimator::MultiSample},       {Method::Equal, Estimator::MultiSample},
    {Method::Equal, Estimator::OneSample},        {Method::Heuristic, Estimator::MultiSample},
    {Method::SigmaSqrtC, Estimator::MultiSample}, {Method::Linear, Estimator::MultiSample},
    {Method::Exact, Estimator::MultiSample},      {Method::Oracle, Estimator::MultiSample}};

}  // namespace

TEST_CASE("the option --envmap-pdf parses plain, compensated, compensated:C, optimal, optimal-pixel:N and :N/P",
          "[compensated]") {
  CHECK_FALSE(parseEnvmapPdf("plain").compensated());
  CHECK(parseEnvmapPdf("plain").plain());
  CHECK(parseEnvmapPdf("optimal").optimal());
  CHECK(envmapPdfName(parseEnvmapPdf("optimal")) == "optimal");
  CHECK(parseEnvmapPdf("compensated").compensated());
  CHECK(parseEnvmapPdf("compensated").envmapFraction == 0.5);
  CHECK(parseEnvmapPdf("compensated:0.25").envmapFraction == 0.25);
  CHECK(parseEnvmapPdf("compensated:1").envmapFraction == 1);
  CHECK(envmapPdfName(parseEnvmapPdf("compensated")) == "compensated:0.5");
  CHECK(envmapPdfName(parseEnvmapPdf("plain")) == "plain");
  CHECK(parseEnvmapPdf("optimal-pixel").cellsAcross == misalloc::kDefaultPixelCellsAcross);
  CHECK(envmapPdfName(parseEnvmapPdf("optimal-pixel")) == "optimal-pixel");
  CHECK(parseEnvmapPdf("optimal-pixel:16").pixelOptimal());
  CHECK(parseEnvmapPdf("optimal-pixel:16").cellsAcross == 16);
  CHECK(envmapPdfName(parseEnvmapPdf("optimal-pixel:4")) == "optimal-pixel:4");
  CHECK(envmapPdfName(parseEnvmapPdf("optimal-pixel:64")) == "optimal-pixel:64");
  CHECK(envmapPdfName(parseEnvmapPdf(fmt::format("optimal-pixel:{}", misalloc::kDefaultPixelCellsAcross))) ==
        "optimal-pixel");
  // The pilot's cells: at most the default's, never more than the render's.
  CHECK(parseEnvmapPdf("optimal-pixel").pilotCellsAcross == misalloc::kDefaultPilotCellsAcross);
  CHECK(parseEnvmapPdf("optimal-pixel:64").pilotCellsAcross == misalloc::kDefaultPilotCellsAcross);
  CHECK(parseEnvmapPdf("optimal-pixel:8").pilotCellsAcross == 8);
  CHECK(parseEnvmapPdf("optimal-pixel:32/8").cellsAcross == 32);
  CHECK(parseEnvmapPdf("optimal-pixel:32/8").pilotCellsAcross == 8);
  CHECK(envmapPdfName(parseEnvmapPdf("optimal-pixel:32/8")) == "optimal-pixel:32/8");
  CHECK(envmapPdfName(parseEnvmapPdf("optimal-pixel:32/32")) == "optimal-pixel:32/32");
  CHECK(envmapPdfName(parseEnvmapPdf("optimal-pixel:32/16")) == "optimal-pixel");
  CHECK(envmapPdfName(parseEnvmapPdf("optimal-pixel:8/8")) == "optimal-pixel:8");
  for (const char* bad : {"compensated:0", "compensated:1.5", "compensated:-1", "compensated:x", "compensated:",
                          "optimal:0.5", "Plain", "optimal-pixel:", "optimal-pixel:2", "optimal-pixel:12",
                          "optimal-pixel:128", "optimal-pixel:16x8", "optimal-pixel:-16", "optimal-pixel:0"})
    CHECK_THROWS_AS(parseEnvmapPdf(bad), InputError);
  for (const char* bad : {"optimal-pixel:16/32", "optimal-pixel:32/", "optimal-pixel:32/2", "optimal-pixel:32/12",
                          "optimal-pixel:/16", "optimal-pixel:32/16/8", "optimal-pixel:32/16x"})
    CHECK_THROWS_AS(parseEnvmapPdf(bad), InputError);
}

TEST_CASE("compare names the optimal pdf per pixel's cells and the pilot's where they are not the default's",
          "[compensated][compare]") {
  // Each case's runs go to a folder of its label: two cell counts must not share one.
  SceneOptions o;
  o.envmap = "forest_slope";
  o.shape = "spheres";
  o.envmapPdf = parseEnvmapPdf("optimal-pixel");
  CHECK(misalloc::caseLabel(o) == "forest_slope-spheres-optimal-pixel");
  o.envmapPdf = parseEnvmapPdf("optimal-pixel:16");
  CHECK(misalloc::caseLabel(o) == "forest_slope-spheres-optimal-pixel-16");
  o.envmapPdf = parseEnvmapPdf("optimal-pixel:32/8");
  CHECK(misalloc::caseLabel(o) == "forest_slope-spheres-optimal-pixel-32-8");
}

TEST_CASE("L̄ of a cos^K map is 1/(2(K+1)) and the compensated pdf drops every texel at or below it", "[compensated]") {
  for (double K : {0.5, 1.0, 3.0, 20.0})
    for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
      Scene scene = compensatedScene(fmt::format("cosk:{}", K), "uniform:0.5,0.5,5", "compensated", sampler, false, 2);
      const EnvmapTables& t = scene.tables;
      INFO(fmt::format("K {} cdf {}", K, t.useCdf));
      // The rasteriser's texel averages take the midpoint rule over 16 sub-rows.
      CHECK(t.meanLuminance == Approx(1 / (2 * (K + 1))).epsilon(1e-4));
      REQUIRE(t.pdf.compensated());
      const double threshold = 2 * (1 - 0.5) * t.meanLuminance;
      double sum = 0, zeros = 0;
      size_t wrong = 0;
      for (size_t i = 0; i < t.texels.size() / 4; ++i) {
        const double p = t.texels[4 * i + 3];
        sum += p;
        zeros += p == 0;
        // Rows whose luminance is within float rounding of L̄ may go either way.
        if (std::abs(luminanceOfTexel(t, i) - threshold) > 1e-5 * threshold)
          wrong += (luminanceOfTexel(t, i) > threshold) != (p > 0);
      }
      CHECK(wrong == 0);
      CHECK(sum == Approx(1).epsilon(1e-5));
      CHECK(zeros / double(t.texels.size() / 4) == Approx(t.zeroTexelFraction).margin(1e-3));
    }
}

TEST_CASE("the alias table stores probabilities ∝ (L − 2(1−C)·L̄) sin θ", "[compensated]") {
  for (double C : {0.5, 0.25, 0.9}) {
    Scene scene = compensatedScene("sun:30,40,5,100", "uniform:0.5,0.5,5", fmt::format("compensated:{}", C),
                                   EnvmapSampler::Alias, false, 2);
    const EnvmapTables& t = scene.tables;
    std::vector<double> w(t.texels.size() / 4);
    double total = 0;
    for (size_t i = 0; i < w.size(); ++i) {
      const double sinTheta = std::sin(M_PI * (double(i / t.width) + 0.5) / t.height);
      w[i] = std::max(0.0, luminanceOfTexel(t, i) - 2 * (1 - C) * t.meanLuminance) * sinTheta;
      total += w[i];
    }
    double error = 0;
    for (size_t i = 0; i < w.size(); ++i) error += std::abs(w[i] / total - t.texels[4 * i + 3]);
    INFO("C " << C);
    CHECK(error < 1e-5);
  }
}

TEST_CASE("a compensated pdf that leaves no texel falls back to plain, and the report says so", "[compensated]") {
  for (const char* pdf : {"compensated", "compensated:0.3"}) {
    Scene scene = compensatedScene("constant:2", "uniform:0.5,0.5,5", pdf, EnvmapSampler::Cdf, false, 2);
    INFO(pdf);
    CHECK(scene.tables.requestedPdf.compensated());
    CHECK_FALSE(scene.tables.pdf.compensated());
    CHECK_FALSE(scene.tables.uniformFallback);
    nlohmann::json j = sceneJson(scene)["envmap_pdf"];
    CHECK(j["requested"] == envmapPdfName(parseEnvmapPdf(pdf)));
    CHECK(j["used"] == "plain");
    CHECK(j["fallback_to_plain"] == true);
    CHECK(j["mean_luminance"].get<double>() == Approx(2).epsilon(1e-6));
  }
  // C > 1/2 subtracts less than the constant: every texel stays, so no fallback.
  Scene kept = compensatedScene("constant:2", "uniform:0.5,0.5,5", "compensated:0.75", EnvmapSampler::Alias, false, 2);
  CHECK(kept.tables.pdf.compensated());
  CHECK(kept.tables.zeroTexelFraction == 0);
  CHECK(sceneJson(kept)["envmap_pdf"]["fallback_to_plain"] == false);
  // The reference's scene is plain whatever the render's pdf.
  Scene sun = compensatedScene("sun", "uniform:0.5,0.5,5", "compensated", EnvmapSampler::Alias, false, 2);
  CHECK(sun.tables.pdf.compensated());
  CHECK_FALSE(withPlainEnvmapPdf(sun).tables.pdf.compensated());
  CHECK(referenceKey(withPlainEnvmapPdf(sun), 64) == referenceKey(sun, 64));
}

TEST_CASE("the compensated pdf refuses schedules that could skip BRDF sampling", "[compensated][bad-input]") {
  const EnvmapPdf plain, compensated = parseEnvmapPdf("compensated");
  auto scene = [](const EnvmapPdf& pdf, int M) {
    SceneOptions o;
    o.envmapPdf = pdf;
    o.splitBrdf = M == 3;
    return o;
  };
  AdaptiveOptions options;
  CHECK_THROWS_WITH(requireValidRun(scene(compensated, 2), Method::Envmap, Estimator::MultiSample, 64, options),
                    Catch::Contains("--method envmap with --envmap-pdf compensated:0.5"));
  CHECK_NOTHROW(requireValidRun(scene(plain, 2), Method::Envmap, Estimator::MultiSample, 64, options));
  CHECK_NOTHROW(requireValidRun(scene(compensated, 2), Method::Brdf, Estimator::MultiSample, 1, options));
  // One sample, one-sample MIS: the equal split's probabilities are n_k/N = (1, 0),
  // envmap sampling alone.
  CHECK_THROWS_AS(requireValidRun(scene(compensated, 2), Method::Equal, Estimator::OneSample, 1, options), InputError);
  CHECK_NOTHROW(requireValidRun(scene(compensated, 2), Method::Equal, Estimator::OneSample, 2, options));
  CHECK_THROWS_AS(requireValidRun(scene(compensated, 2), Method::Equal, Estimator::MultiSample, 1, options),
                  InputError);
  CHECK_THROWS_AS(requireValidRun(scene(compensated, 3), Method::Oracle, Estimator::MultiSample, 2, options),
                  InputError);
  // 9 spp in 4 stages: a pilot of 4, then stages of 2, 1, 1, 1: the floor cannot give
  // both techniques one.
  AdaptiveOptions fourStages = options;
  fourStages.stages = 4;
  CHECK_THROWS_WITH(requireValidRun(scene(compensated, 2), Method::Heuristic, Estimator::MultiSample, 9, fourStages),
                    Catch::Contains("a stage of 1 sample(s)"));
  CHECK_NOTHROW(requireValidRun(scene(compensated, 2), Method::Heuristic, Estimator::MultiSample, 12, fourStages));
  CHECK_NOTHROW(requireValidRun(scene(compensated, 2), Method::Heuristic, Estimator::MultiSample, 9, options));

  TempDir dir("compensated");
  const std::string outputs = fmt::format("--out {} --report {} --reference none", (dir.path / "r.exr").string(),
                                          (dir.path / "r.json").string());
  auto r = runMisalloc(fmt::format("render --size 8x8 --spp 4 --method envmap --envmap-pdf compensated {}", outputs));
  INFO(r.output);
  CHECK(r.exitCode == 2);
  CHECK(r.output.find("--method envmap with --envmap-pdf compensated:0.5") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir.path / "r.exr"));
  auto bad = runMisalloc(fmt::format("render --size 8x8 --spp 4 --envmap-pdf compensated:2 {}", outputs));
  CHECK(bad.exitCode == 2);
  CHECK(bad.output.find("must lie in (0, 1]") != std::string::npos);
}

TEST_CASE("every method is unbiased with the compensated pdf against [HS14] eq. 6.17", "[compensated][unbiased]") {
  struct Case {
    double rhoD, n, K;
    const char* pdf;
  };
  const Case cases[] = {{0.5, 5, 1, "compensated"}, {0.2, 50, 3, "compensated:0.25"}, {0.9, 20, 0.5, "compensated"}};
  uint64_t seed = 900;
  BiasFamily family(0.02);
  for (const Case& c : cases) {
    const double expected = closedForm(c.rhoD, 1 - c.rhoD, c.n, c.K);
    for (bool split : {false, true})
      for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
        // The small size (tests/TestSize.h) keeps the first case, unsplit, with the
        // alias sampler, under the seeds it has in the full sweep.
        if (smallTestSize() && (&c != &cases[0] || split || s != EnvmapSampler::Alias)) {
          seed += kMethodsWithBrdfSampling.size();
          continue;
        }
        Scene scene = compensatedScene(fmt::format("cosk:{}", c.K),
                                       fmt::format("uniform:{},{},{}", c.rhoD, 1 - c.rhoD, c.n), c.pdf, s, split);
        REQUIRE(scene.tables.pdf.compensated());
        for (auto [m, e] : kMethodsWithBrdfSampling) {
          addSized(family,
                   fmt::format("rhoD {} n {} K {} {} split {} cdf {} {} one-sample {}", c.rhoD, c.n, c.K, c.pdf, split,
                               s == EnvmapSampler::Cdf, methodName(m), e == Estimator::OneSample),
                   expected, 60, 60, ++seed, [&](int spp, uint64_t sd) { return imageMean(scene, m, e, spp, sd); });
        }
      }
  }
  checkFamily(family);
}

TEST_CASE("every method is unbiased with the optimal pdf against [HS14] eq. 6.17", "[compensated][optimal][unbiased]") {
  // One BRDF bin (a uniform grid), whose entry for each share is eq. 9 for that very
  // BRDF: most blocks of the cos^K sky are left to BRDF sampling.
  struct Case {
    double rhoD, n, K;
  };
  const Case cases[] = {{0.5, 5, 1}, {0.2, 50, 3}, {0.9, 20, 0.5}};
  // The CDF sampler draws the bank's blocks for the first case only: the blocks' texels
  // and the entries are the alias sampler's.
  uint64_t seed = 1900;
  BiasFamily family(0.02);
  for (const Case& c : cases)
    for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
      if ((s == EnvmapSampler::Cdf && &c != &cases[0]) ||
          (smallTestSize() && (&c != &cases[0] || s != EnvmapSampler::Alias))) {
        seed += kMethodsWithBrdfSampling.size();
        continue;
      }
      const double expected = closedForm(c.rhoD, 1 - c.rhoD, c.n, c.K);
      Scene scene = compensatedScene(fmt::format("cosk:{}", c.K),
                                     fmt::format("uniform:{},{},{}", c.rhoD, 1 - c.rhoD, c.n), "optimal", s);
      REQUIRE(scene.tables.hasBank());
      REQUIRE(scene.tables.bankVariances.entriesWithNegativeEq5 > 0);
      for (auto [m, e] : kMethodsWithBrdfSampling) {
        addSized(family,
                 fmt::format("rhoD {} n {} K {} optimal cdf {} {} one-sample {}", c.rhoD, c.n, c.K,
                             s == EnvmapSampler::Cdf, methodName(m), e == Estimator::OneSample),
                 expected, 60, 60, ++seed, [&](int spp, uint64_t sd) { return imageMean(scene, m, e, spp, sd); });
      }
    }
  checkFamily(family);
}

TEST_CASE("every method is unbiased with the optimal pdf per pixel against [HS14] eq. 6.17",
          "[compensated][optimal][unbiased]") {
  // Each stage builds each pixel's table for its own envmap share: the staged methods
  // run tables of other shares than the pilot's.
  struct Case {
    double rhoD, n, K;
  };
  const Case cases[] = {{0.5, 5, 1}, {0.2, 50, 3}, {0.9, 20, 0.5}};
  uint64_t seed = 2900;
  BiasFamily family(0.02);
  for (const Case& c : cases) {
    if (smallTestSize() && &c != &cases[0]) {
      seed += kMethodsWithBrdfSampling.size();
      continue;
    }
    const double expected = closedForm(c.rhoD, 1 - c.rhoD, c.n, c.K);
    Scene scene = compensatedScene(fmt::format("cosk:{}", c.K),
                                   fmt::format("uniform:{},{},{}", c.rhoD, 1 - c.rhoD, c.n), "optimal-pixel");
    REQUIRE(scene.tables.pixelCells > 0);
    for (auto [m, e] : kMethodsWithBrdfSampling) {
      addSized(family,
               fmt::format("rhoD {} n {} K {} optimal-pixel {} one-sample {}", c.rhoD, c.n, c.K, methodName(m),
                           e == Estimator::OneSample),
               expected, 60, 60, ++seed, [&](int spp, uint64_t sd) { return imageMean(scene, m, e, spp, sd); });
    }
  }
  // Cells other than the default's: the fewest, and the most the search reaches on this
  // 512-texel map's 64 × 32.
  const Case& c = cases[0];
  const double expected = closedForm(c.rhoD, 1 - c.rhoD, c.n, c.K);
  for (const char* pdf : {"optimal-pixel:4", "optimal-pixel:64"}) {
    Scene scene =
        compensatedScene(fmt::format("cosk:{}", c.K), fmt::format("uniform:{},{},{}", c.rhoD, 1 - c.rhoD, c.n), pdf);
    REQUIRE(scene.tables.pixelCells == scene.tables.pdf.cellsAcross * scene.tables.pdf.cellsAcross / 2);
    for (Method m : {Method::Equal, Method::Exact})
      addSized(family, fmt::format("rhoD {} n {} K {} {} {}", c.rhoD, c.n, c.K, pdf, methodName(m)), expected, 60, 60,
               ++seed, [&](int spp, uint64_t sd) { return imageMean(scene, m, Estimator::MultiSample, spp, sd); });
  }
  checkFamily(family);
}

TEST_CASE("the optimal pdf per pixel refuses envmap sampling alone and split BRDF lobes, and reports its cells",
          "[compensated][optimal][bad-input]") {
  SceneOptions pixel;
  pixel.envmapPdf = parseEnvmapPdf("optimal-pixel");
  CHECK(envmapPdfName(pixel.envmapPdf) == "optimal-pixel");
  CHECK_THROWS_WITH(requireValidRun(pixel, Method::Envmap, Estimator::MultiSample, 64, {}),
                    Catch::Contains("--method envmap with --envmap-pdf optimal-pixel"));
  CHECK_THROWS_WITH(compensatedScene("sun", "seed000", "optimal-pixel", EnvmapSampler::Alias, true),
                    Catch::Contains("--envmap-pdf optimal-pixel with --split-brdf: not implemented"));

  TempDir dir("optimal-pixel");
  const std::string outputs = fmt::format("--out {} --report {} --reference none", (dir.path / "r.exr").string(),
                                          (dir.path / "r.json").string());
  auto ok = runMisalloc(
      fmt::format("render --scene sphere --size 16x16 --spp 8 --method equal --envmap-pdf optimal-pixel {}", outputs));
  INFO(ok.output);
  REQUIRE(ok.exitCode == 0);
  std::ifstream in(dir.path / "r.json");
  const nlohmann::json pdf = nlohmann::json::parse(in)["scene"]["envmap_pdf"];
  CHECK(pdf["used"] == "optimal-pixel");
  CHECK(pdf["fallback_to_plain"] == false);
  CHECK(pdf["pixel_cells"]["across"] == misalloc::kDefaultPixelCellsAcross);
  CHECK(pdf["pixel_cells"]["cells"] == misalloc::kDefaultPixelCellsAcross * misalloc::kDefaultPixelCellsAcross / 2);

  // Its cells asked for, and refused where the search could not reach them or a cell
  // would not be a block of texels; nothing written then. On the C++ reference: the
  // cells are the scene's, and a kernel built for them would only cost CI its compile.
  std::filesystem::remove(dir.path / "r.json");
  auto sixteen = runMisalloc(fmt::format(
      "render --scene sphere --size 16x16 --spp 8 --method equal --envmap-pdf optimal-pixel:16 --device host {}",
      outputs));
  REQUIRE(sixteen.exitCode == 0);
  std::ifstream sixteenIn(dir.path / "r.json");
  const nlohmann::json pdf16 = nlohmann::json::parse(sixteenIn)["scene"]["envmap_pdf"];
  CHECK(pdf16["requested"] == "optimal-pixel:16");
  CHECK(pdf16["used"] == "optimal-pixel:16");
  CHECK(pdf16["pixel_cells"]["across"] == 16);
  CHECK(pdf16["pixel_cells"]["cells"] == 128);
  for (const char* bad : {"optimal-pixel:24", "optimal-pixel:128"}) {
    TempDir badDir("optimal-pixel-bad");
    auto refused = runMisalloc(fmt::format("render --scene sphere --size 16x16 --spp 8 --envmap-pdf {} --out {}", bad,
                                           (badDir.path / "r.exr").string()));
    INFO(refused.output);
    CHECK(refused.exitCode != 0);
    CHECK(refused.output.find("N, the cells across the map, must be a power of two from 4 to 64") != std::string::npos);
    CHECK(std::filesystem::is_empty(badDir.path));
  }

  auto black = runMisalloc(fmt::format(
      "render --size 8x8 --spp 8 --method equal --envmap constant:0 --envmap-pdf optimal-pixel {}", outputs));
  REQUIRE(black.exitCode == 0);
  CHECK(black.output.find("--envmap-pdf optimal-pixel falls back to plain") != std::string::npos);
}

TEST_CASE("the optimal pdf refuses envmap sampling alone and split BRDF lobes, and reports its bank",
          "[compensated][optimal][bad-input]") {
  SceneOptions optimal;
  optimal.envmapPdf = parseEnvmapPdf("optimal");
  CHECK_THROWS_WITH(requireValidRun(optimal, Method::Envmap, Estimator::MultiSample, 64, {}),
                    Catch::Contains("--method envmap with --envmap-pdf optimal"));
  CHECK_THROWS_WITH(compensatedScene("sun", "seed000", "optimal", EnvmapSampler::Alias, true),
                    Catch::Contains("--envmap-pdf optimal with --split-brdf: not implemented"));

  TempDir dir("optimal");
  const std::string outputs = fmt::format("--out {} --report {} --reference none", (dir.path / "r.exr").string(),
                                          (dir.path / "r.json").string());
  auto split = runMisalloc(fmt::format("render --size 8x8 --spp 8 --split-brdf --envmap-pdf optimal {}", outputs));
  CHECK(split.exitCode == 2);
  CHECK(split.output.find("not implemented") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir.path / "r.exr"));

  auto ok = runMisalloc(fmt::format("render --size 16x8 --spp 8 --method equal --envmap-pdf optimal {}", outputs));
  INFO(ok.output);
  REQUIRE(ok.exitCode == 0);
  std::ifstream in(dir.path / "r.json");
  const nlohmann::json pdf = nlohmann::json::parse(in)["scene"]["envmap_pdf"];
  CHECK(pdf["used"] == "optimal");
  CHECK(pdf["fallback_to_plain"] == false);
  CHECK(pdf["bank"]["entries"] == pdf["bank"]["brdf_bins"].get<int>() * 3);
  CHECK(pdf["bank"]["one_sample_variance_eq6_over_eq9_max"].get<double>() >= 1);

  auto black =
      runMisalloc(fmt::format("render --size 8x8 --spp 8 --method equal --envmap constant:0 "
                              "--envmap-pdf optimal {}",
                              outputs));
  REQUIRE(black.exitCode == 0);
  CHECK(black.output.find("--envmap-pdf optimal falls back to plain") != std::string::npos);
  std::ifstream blackReport(dir.path / "r.json");
  CHECK(nlohmann::json::parse(blackReport)["scene"]["envmap_pdf"]["fallback_to_plain"] == true);
}

TEST_CASE("compare runs each scene with each envmap pdf and compares them with equal and plain",
          "[compensated][compare]") {
  // Two pdfs of one scene: the compensated one halves equal's MSE at the same times, so
  // under the Monte Carlo law MSE ∝ 1/t plain equal needs twice as long.
  Comparison c;
  for (const char* pdf : {"plain", "compensated:0.5"}) {
    nlohmann::json scene = {{"envmap", "m"}, {"envmap_pdf", {{"requested", pdf}}}};
    const std::string label = std::string("m-") + pdf;
    c.cases.push_back({label, scene, {"envmap", "brdf"}, {1, 1}, "--cost", "analytic", 0, "test"});
    for (int budget : {10, 20})
      c.runs.push_back(record(label, Method::Equal, budget, 0, 0.01 * budget,
                              (pdf == std::string("plain") ? 1e-4 : 0.5e-4) * 10 / budget));
  }
  CompareOptions o;
  o.methods = {Method::Equal};
  o.budgets = {10, 20};
  o.repeats = 1;
  o.tableBudget = 20;
  Summary s = summarize(c, o);
  TextTable t = envmapPdfSpeedUpTable(s, 20);
  REQUIRE(t.rows.size() == 2);
  CHECK(t.header == std::vector<std::string>{"method", "pdf", "m-plain", "geometric mean"});
  CHECK(t.rows[0][1].text == "plain");
  CHECK(t.rows[0][2].text == "1.00");
  CHECK(t.rows[1][1].text == "compensated:0.5");
  CHECK(t.rows[1][2].text == "~2.00");  // below plain's least error: read past its curve's end
  CHECK(envmapPdfMarkdown(s).find("speed-up over equal with the plain pdf") != std::string::npos);

  CHECK(parseEnvmapPdfList("plain,compensated:0.25").size() == 2);
  CHECK_THROWS_WITH(parseEnvmapPdfList("compensated,compensated:0.5"), Catch::Contains("listed twice"));
  std::vector<CompareCase> cases = casesPerEnvmapPdf({{"x", SceneOptions{}}}, parseEnvmapPdfList("plain,compensated"));
  REQUIRE(cases.size() == 2);
  CHECK(cases[0].label == "forest_slope");
  CHECK(cases[1].label == "forest_slope-comp0.5");

  TempDir dir("compare_pdfs");
  const auto out = dir.path / "out";
  auto r =
      runMisalloc(fmt::format("compare --envmap cosk:2 --size 8x8 --budgets 10,20 --repeats 2 --methods equal,brdf "
                              "--envmap-pdfs plain,compensated --device cpu --out-dir {} --cache-dir {}",
                              out.string(), (dir.path / "cache").string()));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  CHECK(std::filesystem::exists(out / "envmap_pdfs.md"));
  CHECK(std::filesystem::exists(out / "cosk_2-comp0.5/equal_20spp.exr"));
  nlohmann::json runs = nlohmann::json::parse(std::ifstream(out / "runs.json"));
  CHECK(runs["runs"].size() == 2 * 2 * 2 * 2);
  CHECK(runs["cases"][1]["scene"]["envmap_pdf"]["used"] == "compensated:0.5");
  CHECK(runs["cases"][1]["reference"] == "analytic ([HS14] eq. 6.17)");

  auto refused = runMisalloc(fmt::format(
      "compare --envmap cosk:2 --size 8x8 --budgets 10 --envmap-pdfs plain,compensated --out-dir {}", out.string()));
  CHECK(refused.exitCode == 2);
  CHECK(refused.output.find("--method envmap with --envmap-pdf compensated:0.5") != std::string::npos);
}
