// Every estimator is unbiased: against the closed form [HS14] eq. 6.17 (envmap cos^K θ,
// view along the normal) and, where there is none, against each other. Each pixel of a
// uniform grid is an independent estimate of the same value, so the pixel mean has a
// known standard error; fixed seeds make every z-score reproducible.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <vector>

#include "BiasCheck.h"
#include "Error.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "TestSize.h"
#include "render/Render.h"
#include "render/RunChecks.h"
#include "sampling/HostSampler.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

// The bias, relative to the closed form, that each test of the sweeps against [HS14]
// eq. 6.17 detects with probability 0.9 (tests/Statistics.h, BiasFamily).
constexpr double kDetect = 0.02;

MeanAndError renderMean(const Scene& scene, Method method, Estimator estimator, int spp, uint64_t seed) {
  StageResult r = sweepSampler(scene, {estimator, 0, 0})->run(singleStagePlan(scene, method, spp), seed);
  return pixelMean(r.rgb);
}

// `ris` with M candidates on the C++ reference, which computes the kernel's floats
// (tests/test_sampler.cpp): each M is a kernel of its own, which PoCL would compile
// for seconds. The run's checks are left to the caller.
MeanAndError resampledMean(const Scene& scene, int candidates, int spp, uint64_t seed) {
  AdaptiveOptions options;
  options.risCandidates = candidates;
  HostSampler sampler(scene,
                      samplerConfigFor(Method::Ris, Estimator::MultiSample, spp, options, scene.techniqueCount()));
  return pixelMean(sampler.run(singleStagePlan(scene, Method::Ris, spp), seed).rgb);
}

}  // namespace

TEST_CASE("every estimator is unbiased against [HS14] eq. 6.17", "[unbiased]") {
  struct Case {
    double rhoD, n, K;
  };
  const Case cases[] = {{0.5, 5, 1}, {0.2, 50, 3}, {1.0, 1, 0}, {0.05, 100, 0.5}, {0.7, 0.1, 6}};
  // Small test size (the sanitizer build): two BRDFs with every estimator, split and
  // sampler, under the seeds the full sweep gives them.
  const std::vector<int> picked = smallTestSize() ? std::vector<int>{0, 3} : std::vector<int>{0, 1, 2, 3, 4};
  const int rendersPerCase = 16;  // 2 splits × 2 samplers × 4 method-estimator pairs
  BiasFamily family(kDetect);
  for (int i : picked) {
    const Case& c = cases[i];
    uint64_t seed = 100 + uint64_t(rendersPerCase * i);
    const double expected = closedForm(c.rhoD, 1 - c.rhoD, c.n, c.K);
    for (bool split : {false, true}) {
      for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
        Scene scene = smallScene(fmt::format("cosk:{}", c.K), fmt::format("uniform:{},{},{}", c.rhoD, 1 - c.rhoD, c.n),
                                 32, 32, split, s);
        for (Method m : {Method::Envmap, Method::Brdf, Method::Equal}) {
          for (Estimator e : {Estimator::MultiSample, Estimator::OneSample}) {
            if (m != Method::Equal && e == Estimator::OneSample) continue;  // the same estimator
            addSized(family,
                     fmt::format("rhoD {} n {} K {} split {} cdf {} method {} one-sample {}", c.rhoD, c.n, c.K, split,
                                 s == EnvmapSampler::Cdf, methodName(m), e == Estimator::OneSample),
                     expected, 16, 4, ++seed, [&](int spp, uint64_t sd) { return renderMean(scene, m, e, spp, sd); });
          }
        }
      }
    }
  }
  checkFamily(family);
}

TEST_CASE("estimators agree on a real envmap and an oblique view", "[unbiased]") {
  // No closed form: each technique alone and their MIS estimate the same integral.
  const std::vector<double> views = smallTestSize() ? std::vector<double>{89.0} : std::vector<double>{0.0, 60.0, 89.0};
  BiasFamily family(0.03, 3 * 2);
  for (double view : views) {
    Scene scene = smallScene("kloofendal_overcast", "uniform:0.3,0.7,20", 32, 32, false, EnvmapSampler::Alias, view);
    const MeanAndError equal = renderMean(scene, Method::Equal, Estimator::MultiSample, 256, 7);
    for (Method m : {Method::Envmap, Method::Brdf})
      addAgreement(family, fmt::format("view {} {} against equal", view, methodName(m)),
                   renderMean(scene, m, Estimator::MultiSample, 256, 8), equal);
  }
  checkFamily(family);
}

TEST_CASE("resampling envmap candidates is unbiased against [HS14] eq. 6.17", "[unbiased][ris]") {
  struct Case {
    double rhoD, n, K;
  };
  const Case cases[] = {{0.5, 5, 1}, {0.2, 50, 3}, {1.0, 1, 0}, {0.05, 100, 0.5}, {0.7, 0.1, 6}};
  // One candidate (envmap sampling), a part of the resampling stream's coins unused, and
  // the most the kernel takes; small test size: two BRDFs.
  const std::vector<int> picked = smallTestSize() ? std::vector<int>{0, 3} : std::vector<int>{0, 1, 2, 3, 4};
  const int candidateCounts[] = {1, 3, kMaxRisCandidates};
  // At 32 spp, one candidate (envmap sampling) of the sharp lobe (ρs 0.95, n 100) sets the
  // bound; its three candidates detect 11 %, sixteen 5 %, the other BRDFs 7 % and less.
  BiasFamily family(0.2, 5 * 2 * 2 * 3);
  for (int i : picked) {
    const Case& c = cases[i];
    uint64_t seed = 700 + uint64_t(16 * i);
    const double expected = closedForm(c.rhoD, 1 - c.rhoD, c.n, c.K);
    for (bool split : {false, true})
      for (EnvmapSampler s : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
        Scene scene = smallScene(fmt::format("cosk:{}", c.K), fmt::format("uniform:{},{},{}", c.rhoD, 1 - c.rhoD, c.n),
                                 32, 32, split, s);
        for (int M : candidateCounts)
          addEstimate(family,
                      fmt::format("rhoD {} n {} K {} split {} cdf {} candidates {}", c.rhoD, c.n, c.K, split,
                                  s == EnvmapSampler::Cdf, M),
                      resampledMean(scene, M, 32, ++seed), expected);
      }
  }
  checkFamily(family);
}

TEST_CASE("resampling from a compensated or optimal envmap pdf is refused: it would be biased",
          "[unbiased][ris][bad-input]") {
  // A sun over a dim sky and a diffuse BRDF: both pdfs are zero over much of the sky,
  // whose radiance BRDF sampling would cover ([Kar19] Sec. 4), so no candidate falls
  // there and its share of the pixel is lost. No closed form: against resampling from
  // the plain pdf, unbiased (above).
  const std::string sun = "sun:40,90,0.5,1e5", diffuse = "uniform:1,0,1";
  const MeanAndError plain = resampledMean(smallScene(sun, diffuse, 32, 32), kDefaultRisCandidates, 64, 800);
  uint64_t seed = 800;
  // Detected: past the family-wise bound of this test's two checks (tests/Statistics.h).
  const double bound = twoSidedNormalBound(sidakLevel(1e-3, 2));
  for (const char* pdf : {"compensated", "optimal"}) {
    const Scene scene = smallScene(sun, diffuse, 32, 32, false, EnvmapSampler::Alias, 0, pdf);
    CHECK_THROWS_WITH(
        requireValidRun(scene.options, Method::Ris, Estimator::MultiSample, 64, {}),
        Catch::Contains(fmt::format("--method ris with --envmap-pdf {}", envmapPdfName(scene.options.envmapPdf))) &&
            Catch::Contains("[TCE05]"));
    const MeanAndError r = resampledMean(scene, kDefaultRisCandidates, 64, ++seed);
    const double z = zScore(r.mean, plain.mean, std::hypot(r.standardError, plain.standardError));
    INFO(fmt::format("{}: mean {} plain {} z {} bound {}", pdf, r.mean, plain.mean, z, bound));
    CHECK(z < -bound);
  }
}
