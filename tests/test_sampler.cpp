// kernels/sample.cl on PoCL against its C++ reference (HostSampler: the same
// functions compiled by g++), and the determinism of the sampling kernel.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cstring>
#include <memory>

#include "Covering.h"
#include "KernelCode.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "alloc/GridSearch.h"
#include "render/Render.h"
#include "sampling/HostSampler.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

// Sums of the same samples in another order (a stage split in two) agree to float
// precision relative to the sum of their magnitudes.
bool closeSums(double a, double b) { return std::abs(a - b) <= 1e-4 * (std::abs(a) + std::abs(b)) + 1e-30; }

}  // namespace

// Neither compiler contracts a*b + c (kernels/sample.cl), so PoCL and g++ compute the
// same floats in the same order: equal bit for bit, with the product technique too. The
// optimal pdf's bank (M = 2 only) is read through every BRDF bin of the grid and, as the
// counts vary, every share. The optimal weights ([Kon19]) run with coefficients of both
// signs that differ per pixel. A cos^K map takes the analytic radiance of
// kernels/envmap.h (MA_ANALYTIC_RADIANCE), which every sweep against [HS14] eq. 6.17 runs on the
// reference. The optimal pdf per pixel builds each pixel's table in its stage, for the
// stage's counts. Per-pixel frames (normals and views anywhere, tests/SceneFixtures.h) with the
// pdfs that allow them, and background pixels among them, which take no samples. A pairwise covering set of map × pdf ×
// techniques × sampler × frames × sampler configuration (tests/Covering.h); MISALLOC_TEST_SIZE=exhaustive runs every
// one.
TEST_CASE("sampleStage and samplePixelStage on PoCL match their C++ reference bit for bit", "[sampler]") {
  SamplerConfig shareColumns{Estimator::MultiSample, 0, 100, kDefaultGridSize};
  shareColumns.shareColumns = true;  // with the optimal pdf
  SamplerConfig optimalWeights{Estimator::MultiSample, MA_STATS_TECHNIQUE | MA_STATS_OPTIMAL, 100};
  optimalWeights.optimalWeights = true;
  const SamplerConfig configs[] = {
      {Estimator::MultiSample, 0, 0},
      {Estimator::OneSample, 0, 0},
      {Estimator::CountIndependent, MA_STATS_BALANCE, 0},
      {Estimator::MultiSample, MA_STATS_TECHNIQUE | MA_STATS_LINEAR, 100},
      shareColumns,
      optimalWeights,
  };
  struct Case {
    std::string map, pdf;
    int techniques;  // the BRDF as one technique (0), split (1), or with the product (2)
    EnvmapSampler sampler;
    bool frames;  // per-pixel frames with background pixels among them, or the flat scene
    int config;
  };
  std::vector<Case> cases;
  std::vector<Configuration> settings;
  for (const std::string map : {"venice_sunset", "cosk:2"})
    for (const std::string pdf : {"plain", "optimal", "optimal-pixel"})
      for (int techniques : {0, 1, 2})
        for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf})
          for (bool frames : {false, true})
            for (int config = 0; config < int(std::size(configs)); ++config) {
              // The optimal pdfs take no split lobes; the one per pixel draws its cells by CDF
              // and its texels by alias tables, whatever the sampler.
              if (techniques == 1 && pdf != "plain") continue;
              if (pdf == "optimal-pixel" && s == EnvmapSampler::Cdf) continue;
              // The product's tables do not depend on the sampler: the CDF sampler with the
              // optimal pdf's bank adds PoCL compiles to CI, no path.
              if (techniques == 2 && pdf == "optimal" && s == EnvmapSampler::Cdf) continue;
              // The optimal pdf's bank and the product's tables are built for one frame; with
              // the optimal pdf per pixel the product comes from each pixel's own cells.
              if (frames && (pdf == "optimal" || (techniques == 2 && pdf != "optimal-pixel"))) continue;
              cases.push_back({map, pdf, techniques, s, frames, config});
              settings.push_back({"map=" + map, "pdf=" + pdf, fmt::format("techniques={}", techniques),
                                  fmt::format("cdf={}", s == EnvmapSampler::Cdf), fmt::format("frames={}", frames),
                                  fmt::format("config={}", config)});
            }
  const std::vector<size_t> chosen = configurationsToRun(settings);
  for (size_t c : chosen) {
    const Case& cs = cases[c];
    const SamplerConfig& config = configs[cs.config];
    const bool split = cs.techniques == 1, product = cs.techniques == 2;
    Scene scene = smallScene(cs.map, "seed000", 24, 16, split, cs.sampler, 0, cs.pdf, product);
    if (cs.frames) {
      giveRandomFrames(scene, 3);
      giveBackground(scene, 5);
    }
    if (cs.pdf == "optimal") REQUIRE(scene.tables.brdfBins > 1);
    StagePlan plan = singleStagePlan(scene, Method::Equal, 50);
    // Counts that differ from pixel to pixel, each technique at least one: work-groups
    // then mix counts (kernels/sample.cl runs each technique's loop for the largest).
    const int M = plan.techniqueCount;
    for (int p = 0; p < scene.pixelCount(); ++p) {
      int32_t* n = plan.counts.data() + size_t(p) * M;
      n[0] = 1 + (p * 7) % 45;
      n[M - 1] = 50 - n[0] - (M - 2) * (1 + p % 3);
      if (M == 3) n[1] = 1 + p % 3;
    }
    leaveOutBackground(scene, plan.counts);
    plan.optimalCoefficients.clear();
    if (config.optimalWeights)
      for (size_t i = 0; i < size_t(scene.pixelCount()) * 3 * M; ++i)
        plan.optimalCoefficients.push_back(0.02f * float(int(i * 37 % 101) - 50));
    Sampler device(testDevice(), scene, config);
    HostSampler host(scene, config);
    size_t mismatches = 0;
    // Two stages, so that the running sums and stored samples carry over, and a last
    // stage without them whose counts span several of samplePixelStage's chunks of
    // terms. On a CPU with the alias sampler samplePixelStage runs every stage but those
    // that keep running sums: the stored samples of the share columns' config too.
    for (int stage = 0; stage < 3; ++stage) {
      const int scale = stage == 2 ? 3 : 1;
      StagePlan s = plan;
      s.keepStatistics = stage < 2;
      s.stageSamples = 50 * scale;
      s.samplesBefore = 50 * stage;
      for (size_t i = 0; i < plan.counts.size(); ++i) {
        s.counts[i] = plan.counts[i] * scale;
        s.firstIndex[i] = uint32_t(plan.counts[i] * stage);
      }
      mismatches += stageMismatches(device.run(s, 42), host.run(s, 42));
    }
    mismatches += differingValues(device.statistics(), host.statistics());
    mismatches += differingValues(device.storedSamples(), host.storedSamples());
    INFO(fmt::format("{} {} split {} product {} cdf {} frames {} estimator {} stats {} stored {} optimal weights {}",
                     cs.map, cs.pdf, split, product, cs.sampler == EnvmapSampler::Cdf, cs.frames, int(config.estimator),
                     config.statsMask, config.sampleCapacity, config.optimalWeights));
    CHECK(mismatches == 0);
  }
}

// A stage launches only the pixels that take samples (sampling/LaunchWork.h,
// coherentPixelOrder). The others' sums are zero, not what an earlier stage left in the
// device's buffers, and their running sums and stored samples stay as they were: the
// C++ reference, which visits every pixel, bit for bit. With and without running sums
// (sampleStage; samplePixelStage on a CPU), on scenes of per-pixel frames.
TEST_CASE("pixels that take no samples in a stage are left out of its launch and sum to zero", "[sampler]") {
  for (const SamplerConfig config :
       {SamplerConfig{Estimator::MultiSample, 0, 0}, SamplerConfig{Estimator::MultiSample, MA_STATS_TECHNIQUE, 40}})
    for (const std::string pdf : {"plain", "optimal-pixel"}) {
      Scene scene = smallScene("venice_sunset", "seed000", 24, 16, false, EnvmapSampler::Alias, 0, pdf);
      giveRandomFrames(scene, 3);
      const int M = scene.techniqueCount(), pixels = scene.pixelCount();
      Sampler device(testDevice(), scene, config);
      HostSampler host(scene, config);
      StagePlan every = singleStagePlan(scene, Method::Equal, 20);
      device.run(every, 5);
      host.run(every, 5);
      // Every third pixel takes no samples in the second stage, whose first indices follow the first's.
      StagePlan some = every;
      for (int p = 0; p < pixels; ++p)
        for (int k = 0; k < M; ++k) {
          const size_t i = size_t(p) * M + k;
          some.firstIndex[i] = uint32_t(every.counts[i]);
          if (p % 3 == 0) some.counts[i] = 0;
        }
      const StageResult a = device.run(some, 5), b = host.run(some, 5);
      size_t nonzero = 0, mismatches = 0;
      for (int p = 0; p < pixels; p += 3) {
        for (int c = 0; c < 3; ++c) nonzero += a.rgb[size_t(p) * 3 + c] != 0;
        for (int k = 0; k < 2 * M; ++k) nonzero += a.moments[size_t(p) * 2 * M + k] != 0;
      }
      mismatches += stageMismatches(a, b);
      mismatches += differingValues(device.statistics(), host.statistics());
      mismatches += differingValues(device.storedSamples(), host.storedSamples());
      INFO(pdf << ", running sums " << config.statsMask << ", stored samples " << config.sampleCapacity);
      CHECK(nonzero == 0);
      CHECK(mismatches == 0);
    }
}

// The optimal pdf per pixel's pilot table (Scene::pilotTables): a stage that keeps
// statistics samples from the coarser cells, the last stage from the scene's own. With
// 32 cells across and the pilot's 16, a stage with stored samples (samplePixelStage on a
// CPU) or running sums (sampleStage) is bit for bit that of a scene of 16 cells across,
// and a stage without statistics that of a scene whose pilot has 32, on the device and
// on the reference alike.
TEST_CASE("a stage that keeps statistics samples from the pilot's cells, the last stage from the scene's",
          "[sampler][optimal]") {
  const auto scene = [](const std::string& pdf) {
    Scene s = smallScene("venice_sunset", "seed000", 24, 16, false, EnvmapSampler::Alias, 0, pdf);
    giveRandomFrames(s, 3);
    return s;
  };
  const Scene coarsePilot = scene("optimal-pixel:32/16"), samePilot = scene("optimal-pixel:32/32"),
              coarse = scene("optimal-pixel:16");
  REQUIRE(coarsePilot.pilotTables.pixelCells == coarse.tables.pixelCells);
  REQUIRE(coarsePilot.tables.pixelCells == 4 * coarse.tables.pixelCells);
  CHECK(samePilot.pilotTables.pixelCells == 0);
  CHECK(coarse.pilotTables.pixelCells == 0);
  // A device's copy leaves them out for samplers that keep no statistics.
  CHECK_THROWS_AS(SceneBuffers(testDevice(), coarsePilot, false).envmap(true), std::logic_error);
  CHECK(SceneBuffers(testDevice(), coarsePilot, true).envmap(true).texels() != nullptr);
  CHECK(SceneBuffers(testDevice(), samePilot, false).envmap(true).texels() != nullptr);
  for (const SamplerConfig config :
       {SamplerConfig{Estimator::MultiSample, 0, 40}, SamplerConfig{Estimator::MultiSample, MA_STATS_TECHNIQUE, 0}})
    for (bool device : {false, true}) {
      INFO(fmt::format("stored samples {}, device {}", config.sampleCapacity, device));
      auto sampler = [&](const Scene& s) -> std::unique_ptr<StageSampler> {
        if (device) return std::make_unique<Sampler>(testDevice(), s, config);
        return std::make_unique<HostSampler>(s, config);
      };
      StagePlan plan = singleStagePlan(coarsePilot, Method::Equal, 40);
      for (int p = 0; p < coarsePilot.pixelCount(); ++p) {
        plan.counts[2 * p] = 4 + (p * 5) % 33;
        plan.counts[2 * p + 1] = 40 - plan.counts[2 * p];
      }
      for (bool keepStatistics : {true, false}) {
        plan.keepStatistics = keepStatistics;
        const StageResult a = sampler(coarsePilot)->run(plan, 9);
        const StageResult b = sampler(keepStatistics ? coarse : samePilot)->run(plan, 9);
        const StageResult other = sampler(keepStatistics ? samePilot : coarse)->run(plan, 9);
        INFO(fmt::format("keeps statistics {}", keepStatistics));
        CHECK(a.rgb == b.rgb);
        CHECK(a.moments == b.moments);
        CHECK(a.rgb != other.rgb);  // the two cell sizes sample differently: the check can fail
      }
    }
}

// With share columns, a stored sample holds the envmap's pdf under each share's table,
// the bank's or the optimal pdf per pixel's; the share its stage drew with must hold
// exactly the pdf the sample was weighted with, and the rest of the record must be what a
// sampler without them stores. The optimal pdf per pixel on the C++ reference alone, which
// the kernel matches bit for bit with share columns (the covering set above); that its
// other columns are the pdfs of their shares' tables, tests/test_envmap.cpp.
TEST_CASE("a stored sample's share columns hold the pdf of each share, its own share's as it was weighted",
          "[sampler][optimal]") {
  for (const std::string pdf : {"optimal", "optimal-pixel"}) {
    INFO(pdf);
    const Scene scene = smallScene("venice_sunset", "seed000", 24, 16, false, EnvmapSampler::Alias, 0, pdf);
    const int shares = scene.tables.shareColumns(), N = 40;
    REQUIRE(shares == 3);
    SamplerConfig techniques{Estimator::MultiSample, 0, N}, withShares = techniques;
    withShares.shareColumns = true;
    REQUIRE(sampleColumns(scene, withShares).count() == shares + 1);
    StagePlan plan = singleStagePlan(scene, Method::Equal, N);
    // Envmap counts 4 … 36 of 40: α_0 from 0.1 to 0.9, every share.
    for (int p = 0; p < scene.pixelCount(); ++p) {
      plan.counts[2 * p] = 4 + (p * 5) % 33;
      plan.counts[2 * p + 1] = N - plan.counts[2 * p];
    }
    for (bool device : {false, true}) {
      if (device && pdf == "optimal-pixel") continue;
      std::unique_ptr<StageSampler> a, b;
      if (device) {
        a = std::make_unique<Sampler>(testDevice(), scene, techniques);
        b = std::make_unique<Sampler>(testDevice(), scene, withShares);
      } else {
        a = std::make_unique<HostSampler>(scene, techniques);
        b = std::make_unique<HostSampler>(scene, withShares);
      }
      a->run(plan, 7);
      b->run(plan, 7);
      const std::vector<float> plain = a->storedSamples(), columns = b->storedSamples();
      size_t mismatches = 0, otherShareDiffers = 0;
      std::vector<int> sharesSeen(shares, 0);
      for (int p = 0; p < scene.pixelCount(); ++p) {
        const int share = kern::bankShareOf(shares, float(plan.counts[2 * p]) / float(N));
        sharesSeen[share] = 1;
        for (int i = 0; i < N; ++i) {
          auto at = [&](const std::vector<float>& s, int q, int c) {
            return s[kern::storedSampleIndex(p, i, q, N, c)];
          };
          const int technique = int(at(plain, 0, 2));
          mismatches += at(columns, 0, 4) != float(technique == 0 ? share : shares);
          mismatches += at(columns, 1, 4) != at(plain, 1, 2);
          mismatches += at(columns, 2 + share, 4) != at(plain, 2, 2);
          mismatches += at(columns, 2 + shares, 4) != at(plain, 3, 2);
          for (int s = 0; s < shares; ++s) otherShareDiffers += s != share && at(columns, 2 + s, 4) != at(plain, 2, 2);
        }
      }
      INFO(fmt::format("device {}", device));
      CHECK(mismatches == 0);
      CHECK(sharesSeen == std::vector<int>(shares, 1));
      CHECK(otherShareDiffers > 0);  // the shares' tables differ: the columns are not copies
    }
  }
}

// A stored sample's value (kernels/stats.h, storedSampleValue): the RMS of f's channels,
// or its luminance with the optimal weights. The stage's luminance moments Σ Y(f)/p_α
// per technique check it: with the optimal weights the stored values reproduce them;
// without, they reproduce them under a grey map, where the two are one number (the
// BRDFs are grey), and not under a coloured one.
TEST_CASE("a stored sample keeps the RMS of its channels, and its luminance with optimal weights", "[sampler]") {
  const int N = 8;
  for (const std::string map : {"rooitou_park", "cosk:2"}) {
    const Scene scene = smallScene(map, "seed000", 24, 16);
    for (bool optimalWeights : {false, true}) {
      SamplerConfig config{Estimator::MultiSample, 0, N};
      config.optimalWeights = optimalWeights;
      if (optimalWeights) config.statsMask |= MA_STATS_OPTIMAL;
      for (bool device : {false, true}) {
        std::unique_ptr<StageSampler> sampler;
        if (device)
          sampler = std::make_unique<Sampler>(testDevice(), scene, config);
        else
          sampler = std::make_unique<HostSampler>(scene, config);
        const StagePlan plan = singleStagePlan(scene, Method::Equal, N);
        const StageResult result = sampler->run(plan, 5);
        const std::vector<float> stored = sampler->storedSamples();
        int pixelsMatching = 0;
        for (int p = 0; p < scene.pixelCount(); ++p) {
          double sums[2] = {0, 0};
          for (int i = 0; i < N; ++i) {
            auto at = [&](int q) { return double(stored[kern::storedSampleIndex(p, i, q, N, 2)]); };
            const double pAlpha = (plan.counts[2 * p] * at(2) + plan.counts[2 * p + 1] * at(3)) / N;
            sums[int(at(0))] += pAlpha > 0 ? at(1) / pAlpha : 0.0;
          }
          bool matches = true;
          for (int k = 0; k < 2; ++k) matches &= closeSums(sums[k], result.moments[(2 * p + k) * 2]);
          pixelsMatching += matches;
        }
        INFO(fmt::format("{}, optimal weights {}, device {}: {} of {} pixels", map, optimalWeights, device,
                         pixelsMatching, scene.pixelCount()));
        if (optimalWeights || map == "cosk:2")
          CHECK(pixelsMatching == scene.pixelCount());
        else
          CHECK(pixelsMatching < scene.pixelCount() / 10);
      }
    }
  }
}

// ris's candidate loop, unrolled in the kernel and a loop in the reference. The default
// candidates on a map whose kernel tests/test_devices.cpp builds too: PoCL compiles an
// unrolled loop for seconds per candidate count (docs/pocl.md). On a cos^K map as well,
// whose analytic radiance the resampling sweeps against [HS14] eq. 6.17 take.
TEST_CASE("resampled sampling on PoCL matches its C++ reference bit for bit", "[sampler][ris]") {
  for (const std::string map : {"rooitou_park", "cosk:2"})
    for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
      const Scene scene = smallScene(map, "seed000", 24, 16, false, s);
      const SamplerConfig config =
          samplerConfigFor(Method::Ris, Estimator::MultiSample, 50, AdaptiveOptions{}, scene.techniqueCount());
      Sampler device(testDevice(), scene, config);
      HostSampler host(scene, config);
      const StagePlan plan = singleStagePlan(scene, Method::Ris, 50);
      const size_t mismatches = stageMismatches(device.run(plan, 42), host.run(plan, 42));
      INFO(fmt::format("{} cdf {}", map, s == EnvmapSampler::Cdf));
      CHECK(mismatches == 0);
    }
}

// With one candidate, resampling keeps the envmap technique's own sample: the same
// random numbers and the same value, f(y) (p̂/p)/p̂ for f/p: two more roundings.
TEST_CASE("one candidate resampled is envmap sampling", "[sampler][ris]") {
  const Scene scene = smallScene("rooitou_park", "seed000", 24, 16);
  AdaptiveOptions options;
  options.risCandidates = 1;
  HostSampler resampled(scene,
                        samplerConfigFor(Method::Ris, Estimator::MultiSample, 32, options, scene.techniqueCount()));
  HostSampler envmap(scene,
                     samplerConfigFor(Method::Envmap, Estimator::MultiSample, 32, options, scene.techniqueCount()));
  StageResult a = resampled.run(singleStagePlan(scene, Method::Ris, 32), 3);
  StageResult b = envmap.run(singleStagePlan(scene, Method::Envmap, 32), 3);
  size_t apart = 0;
  // Sums of positive terms, each within three float roundings of the other's.
  for (size_t i = 0; i < a.rgb.size(); ++i) apart += std::abs(a.rgb[i] - b.rgb[i]) > 4 * 0x1p-24 * b.rgb[i];
  CHECK(apart == 0);
}

TEST_CASE("same seed, device and options give bit-identical results", "[sampler][determinism]") {
  Scene scene = smallScene("rooitou_park", "seed000", 40, 24);
  StagePlan plan = singleStagePlan(scene, Method::Equal, 32);
  Sampler a(testDevice(), scene, {}, 8);
  Sampler b(testDevice(), scene, {}, 16);
  StageResult r1 = a.run(plan, 5), r2 = a.run(plan, 5), r3 = b.run(plan, 5), r4 = a.run(plan, 6);
  auto same = [](const std::vector<double>& x, const std::vector<double>& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0;
  };
  CHECK(same(r1.rgb, r2.rgb));
  CHECK(same(r1.moments, r2.moments));
  CHECK(same(r1.rgb, r3.rgb));  // the work-group size does not change the result
  CHECK_FALSE(same(r1.rgb, r4.rgb));
}

TEST_CASE("later stages continue each technique's random stream", "[sampler]") {
  // Two stages of 32 with the second's first indices after the first's take the same
  // samples as one stage of 64, so the stage estimates average to the same image.
  Scene scene = smallScene("forest_slope", "seed000", 16, 16);
  const int M = scene.techniqueCount(), pixels = scene.pixelCount();
  Sampler sampler(testDevice(), scene);
  StageResult whole = sampler.run(singleStagePlan(scene, Method::Equal, 64), 9);
  StagePlan half = singleStagePlan(scene, Method::Equal, 32);
  StageResult first = sampler.run(half, 9);
  for (int p = 0; p < pixels; ++p)
    for (int k = 0; k < M; ++k) half.firstIndex[size_t(p) * M + k] = uint32_t(half.counts[size_t(p) * M + k]);
  StageResult second = sampler.run(half, 9);
  size_t mismatches = 0;
  for (size_t i = 0; i < whole.rgb.size(); ++i)
    mismatches += !closeSums(whole.rgb[i], 0.5 * (first.rgb[i] + second.rgb[i]));
  CHECK(mismatches == 0);
}
