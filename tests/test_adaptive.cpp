// The batched adaptive methods (render/Render.h): every pixel spends exactly its budget,
// the schedule is what the options say, and the combined estimate is unbiased although
// each stage's counts depend on the samples before it.
#include <fmt/format.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>

#include "BiasCheck.h"
#include "Error.h"
#include "KernelCode.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "render/Render.h"
#include "sampling/HostSampler.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

Rendering renderWith(const Scene& scene, Method method, int spp, uint64_t seed,
                     double imageGainBelow = kDefaultImageGainBelow, int stages = 1) {
  AdaptiveOptions options;
  options.costs.assign(scene.techniqueCount(), 1.0);
  options.imageGainBelow = imageGainBelow;
  options.stages = stages;
  options.oracleSamples = 128;
  const auto sampler =
      sweepSampler(scene, samplerConfigFor(method, Estimator::MultiSample, spp, options, scene.techniqueCount()));
  return render(*sampler, method, options, spp, seed);
}

MeanAndError imageMean(const RgbImage& image) {
  return pixelMean(std::vector<double>(image.rgb.begin(), image.rgb.end()));
}

}  // namespace

TEST_CASE("stage sizes follow the pilot share and sum to the budget", "[adaptive]") {
  for (Method m : {Method::Exact, Method::Heuristic}) {
    CHECK(stageSizes(0.2, 4, 200, 2, m) == std::vector<int>{40, 40, 40, 40, 40});
    CHECK(stageSizes(0.2, 4, 103, 2, m) == std::vector<int>{21, 21, 21, 20, 20});
    CHECK(stageSizes(0.1, 2, 20, 3, m) == std::vector<int>{6, 7, 7});  // at least 2 per technique
    CHECK(stageSizes(0.05, 1, 100, 2, m) == std::vector<int>{5, 95});  // no floor within N/8 or pass within N/4
    CHECK_THROWS_AS(stageSizes(0.2, 4, 6, 2, m), InputError);          // no room after the pilot
    CHECK_THROWS_AS(stageSizes(0.0, 4, 200, 2, m), InputError);
    CHECK_THROWS_AS(stageSizes(0.2, 0, 200, 2, m), InputError);
  }
  // exact's and equal's (--weights optimal) pilots take kPilotSamplesPerTechnique per
  // technique within an eighth of the budget.
  for (Method m : {Method::Exact, Method::Equal}) {
    CHECK(stageSizes(0.05, 1, 200, 2, m) == std::vector<int>{16, 184});
    CHECK(stageSizes(0.05, 1, 200, 3, m) == std::vector<int>{24, 176});
    CHECK(stageSizes(0.05, 2, 800, 2, m) == std::vector<int>{40, 380, 380});  // 5 % is above the floor
    CHECK(stageSizes(0.05, 1, 128, 2, m) == std::vector<int>{16, 112});
  }
  // The per-pixel rules' fill passes of kPilotPassSamples per technique within a quarter of the budget.
  for (Method m : {Method::Heuristic, Method::SigmaSqrtC, Method::Linear}) {
    CHECK(stageSizes(0.05, 1, 200, 2, m) == std::vector<int>{32, 168});
    CHECK(stageSizes(0.05, 1, 200, 3, m) == std::vector<int>{48, 152});
    CHECK(stageSizes(0.05, 2, 800, 2, m) == std::vector<int>{64, 368, 368});
    CHECK(stageSizes(0.05, 1, 128, 2, m) == std::vector<int>{32, 96});
  }
}

TEST_CASE("adaptive methods spend exactly the budget of every pixel", "[adaptive]") {
  Scene scene = smallScene("forest_slope", "seed000", 24, 16, true);
  for (Method m : {Method::Heuristic, Method::SigmaSqrtC, Method::Linear, Method::Exact, Method::Oracle}) {
    Rendering r = renderWith(scene, m, 50, 3);
    const int M = scene.techniqueCount();
    size_t wrong = 0;
    for (int p = 0; p < scene.pixelCount(); ++p) {
      double sum = 0;
      for (int k = 0; k < M; ++k) {
        double a = r.alpha[size_t(p) * M + k];
        wrong += a < 0 || a > 1;
        sum += a;
      }
      wrong += std::abs(sum - 1) > 1e-12;
    }
    INFO(methodName(m));
    CHECK(wrong == 0);
    CHECK(r.stageCount == (methodTraits(m).split == Split::Probed ? 1 : AdaptiveOptions().stages + 1));
  }
}

TEST_CASE("adaptive estimates are unbiased against [HS14] eq. 6.17", "[adaptive][unbiased]") {
  // Each pixel of a uniform grid runs its own adaptive schedule on its own samples, its
  // α and its pilot's weight pooled from its neighbours' pilots. Given the pilots, the
  // stages after them are independent across pixels, and each pixel's estimate is
  // unbiased; what pooling correlates between neighbours is second order in the
  // weights' fluctuations, so the pixel mean's standard error is taken as that of
  // independent pixels.
  struct Case {
    double rhoD, n, K;
  };
  const Case cases[] = {{0.5, 5, 1}, {0.2, 50, 3}, {0.9, 20, 0.5}};
  uint64_t seed = 500;
  BiasFamily family(0.02);
  for (const Case& c : cases) {
    const double expected = closedForm(c.rhoD, 1 - c.rhoD, c.n, c.K);
    for (bool split : {false, true}) {
      Scene scene = smallScene(fmt::format("cosk:{}", c.K), fmt::format("uniform:{},{},{}", c.rhoD, 1 - c.rhoD, c.n),
                               32, 32, split);
      for (Method m : {Method::Heuristic, Method::SigmaSqrtC, Method::Linear, Method::Exact, Method::Oracle}) {
        addSized(family, fmt::format("rhoD {} n {} K {} split {} {}", c.rhoD, c.n, c.K, split, methodName(m)), expected,
                 60, 60, ++seed, [&](int spp, uint64_t sd) { return imageMean(renderWith(scene, m, spp, sd).image); });
      }
    }
  }
  checkFamily(family);
}

TEST_CASE("adaptive renders are bit-identical for the same seed", "[adaptive][determinism]") {
  Scene scene = smallScene("rooitou_park", "seed000", 24, 16);
  for (Method m : {Method::Heuristic, Method::Linear, Method::Exact}) {
    Rendering a = renderWith(scene, m, 40, 11), b = renderWith(scene, m, 40, 11);
    CHECK(std::memcmp(a.image.rgb.data(), b.image.rgb.data(), a.image.rgb.size() * sizeof(float)) == 0);
    CHECK(a.alpha == b.alpha);
  }
}

TEST_CASE("grid-search renders on the C++ reference sampler take the device's counts", "[adaptive]") {
  // Both samplers store one stage at a time (and keep running sums between the
  // searches, where a render searches more than once); their samples agree to an ulp or so, which can flip a selection
  // whose neighbours score within float noise (tests/test_exact.cpp), so a few pixels differ.
  Scene scene = smallScene("rooitou_park", "seed000", 24, 16, true);
  for (Method m : {Method::Exact, Method::Oracle}) {
    AdaptiveOptions options;
    options.costs.assign(scene.techniqueCount(), 1.0);
    options.oracleSamples = 128;
    SamplerConfig config = samplerConfigFor(m, Estimator::MultiSample, 60, options, scene.techniqueCount());
    Sampler device(testDevice(), scene, config);
    HostSampler host(scene, config);
    Rendering a = render(device, m, options, 60, 5), b = render(host, m, options, 60, 5);
    const int M = scene.techniqueCount();
    int differ = 0;
    for (int p = 0; p < scene.pixelCount(); ++p)
      differ += !std::equal(a.alpha.begin() + p * M, a.alpha.begin() + (p + 1) * M, b.alpha.begin() + p * M);
    INFO(fmt::format("{}: {} of {} pixels differ", methodName(m), differ, scene.pixelCount()));
    CHECK(differ <= scene.pixelCount() / 50);
    CHECK(a.statisticsBytesPerPixel == b.statisticsBytesPerPixel);
  }
}

TEST_CASE("the skip rule adapts where the window's gain is MA_SKIP_Z standard errors above zero", "[adaptive][skip]") {
  // Scores are −cost × variance: equal counts at −1, the best combination at −0.9 (a
  // predicted gain of 10 %), Σ d_q = 0.1 over a window of 24 pixels whose d_q spread
  // so that Σ d_q is `z` standard errors above zero.
  const float equal = -1.0f, best = -0.9f, sumD = 0.1f, count = 24.0f;
  auto sumD2At = [&](double z) {
    const double variance = double(sumD) * sumD / (count * z * z);
    return float(variance * (count - 1) + double(sumD) * sumD / count);
  };
  CHECK(kern::skipsAdapting(best, equal, 0.02f, sumD, sumD2At(1.1 * MA_SKIP_Z), count) == 0);
  CHECK(kern::skipsAdapting(best, equal, 0.02f, sumD, sumD2At(0.9 * MA_SKIP_Z), count) == 1);
  // Below the least gain, however significant; a single pixel is not tested.
  CHECK(kern::skipsAdapting(best, equal, 0.2f, sumD, sumD2At(10 * MA_SKIP_Z), count) == 1);
  CHECK(kern::skipsAdapting(best, equal, 0.02f, sumD, sumD * sumD, 1.0f) == 0);
  CHECK(kern::skipsAdapting(NAN, equal, 0.02f, sumD, sumD2At(10 * MA_SKIP_Z), count) == 1);
}

TEST_CASE("the skip rule keeps equal counts where adapting cannot pay, and only there", "[adaptive][skip]") {
  // A cos θ sky over a diffuse surface: the envmap pdf and BRDF sampling are both
  // cos θ/π (up to the texels), so V(α) is flat and no α gains anything.
  // Pure noise adapts where the best of the grid's noisy scores beats equal counts by
  // --skip-below and MA_SKIP_Z standard errors of the window's differences. At one
  // standard error that is a t-test at P(T > 1) ≈ 17 % for one combination; the search picks the best of 80 on
  // the same samples, so more windows pass: 33 % of the pixels here over 8 seeds (46 %
  // without the significance test, none at three standard errors). The rule's purpose
  // is the gain it lets through where there is one (docs/results.md, "The skip rule's
  // significance"); here, where no α gains anything, most pixels still keep equal
  // counts, and every pixel that skips splits every stage equally.
  // The whole-image rule is off: it would keep equal counts for all of this image.
  Scene flat = smallScene("cosk:1", "uniform:1,0,1", 24, 16);
  size_t adapted = 0;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    Rendering r = renderWith(flat, Method::Exact, 100, seed, 0.0);
    adapted += flat.pixelCount() - r.skippedPixels;
    // Equal counts in every stage: the odd pilot of 5 and stage of 95 give technique 0
    // one sample more in each.
    size_t equalSplit = 0;
    for (int p = 0; p < flat.pixelCount(); ++p) equalSplit += r.alpha[size_t(p) * 2] == 0.51;
    CHECK(equalSplit == r.skippedPixels);
  }
  INFO(fmt::format("{} of {} pixels adapted", adapted, 8 * flat.pixelCount()));
  CHECK(adapted < size_t(8 * flat.pixelCount()) / 2);
  // A constant sky over the same surface: BRDF sampling alone has zero variance, so
  // equal counts are far from the best α and the pixels adapt towards BRDF sampling.
  // A pilot of 5 samples gives noisy per-pixel differences in places, where the skip
  // rule's significance test holds back: a few pixels at most.
  Scene constant = smallScene("constant", "uniform:1,0,1", 24, 16);
  Rendering r = renderWith(constant, Method::Exact, 100, 9);
  CHECK(r.skippedPixels <= size_t(constant.pixelCount()) / 10);
  for (int p = 0; p < constant.pixelCount(); ++p)
    CHECK((r.alpha[size_t(p) * 2 + 1] > 0.9 || r.alpha[size_t(p) * 2] == 0.51));
}

TEST_CASE("the pilot weighs less where the neighbours predict that alpha beats equal counts", "[adaptive]") {
  // A constant sky over a diffuse surface: BRDF sampling alone has no variance, so the
  // pilot's equal counts are far worse than the α after it and weigh less than their share
  // (host/alloc/StageWeights.cpp, pilotWeight). With --pool 0 a pixel has no neighbours to
  // predict the ratio from, and the pilot keeps its share N_0/N = 5/100.
  Scene constant = smallScene("constant", "uniform:1,0,1", 24, 16);
  AdaptiveOptions options;
  options.costs = {1.0, 1.0};
  Sampler sampler(testDevice(), constant,
                  samplerConfigFor(Method::Exact, Estimator::MultiSample, 100, options, constant.techniqueCount()));
  Rendering pooled = render(sampler, Method::Exact, options, 100, 9);
  CHECK(pooled.meanPilotWeight < 0.5 * 0.05);
  options.poolRadius = 0;
  Rendering own = render(sampler, Method::Exact, options, 100, 9);
  CHECK(own.meanPilotWeight == Approx(0.05).epsilon(1e-12));
  // The flat case of the skip rule: nothing to gain, and the pilot keeps its share
  // where the pixels skip.
  Scene flat = smallScene("cosk:1", "uniform:1,0,1", 24, 16);
  Rendering skipped = renderWith(flat, Method::Exact, 100, 9);
  CHECK(skipped.meanPilotWeight ==
        Approx(0.05).margin(0.05 * double(flat.pixelCount() - skipped.skippedPixels) / flat.pixelCount()));
}

TEST_CASE("exact keeps equal counts for the whole image where its held-out pilot predicts no gain",
          "[adaptive][image]") {
  // The flat case of the skip rule: no α gains much, but a third of the pixels adapt to
  // noise (above). The pixels' own samples, which did not choose their α, predict the
  // image's gain without that selection's optimism: 1.006 in geometric mean over 8
  // seeds (0.996–1.016 each), against 1.017 (1.009–1.026) where the prediction takes the
  // ratio V(equal)/V(α) that the neighbours who chose α predict (a bug planted once in
  // the kernel's and the reference's held-out variance). At equal costs the predicted
  // gain is the variances' ratio alone.
  Scene flat = smallScene("cosk:1", "uniform:1,0,1", 24, 16);
  double heldOut = 0;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    Rendering adapting = renderWith(flat, Method::Exact, 100, seed, 0.0);
    REQUIRE(adapting.predictedGain);
    CHECK_FALSE(adapting.keptEqualCounts);
    heldOut += std::log(*adapting.predictedGain) / 8;
  }
  INFO(fmt::format("held-out gain {:.4f}, geometric mean over 8 seeds", std::exp(heldOut)));
  CHECK(std::exp(heldOut) < 1.012);
  // Below the rule's threshold the whole image keeps equal counts, and says so: every
  // pixel splits the stage after the pilot equally, in one stage whatever --stages says,
  // and the pilot keeps its share.
  for (int stages : {1, 3}) {
    Rendering kept = renderWith(flat, Method::Exact, 100, 3, 1.5, stages);
    REQUIRE(kept.predictedGain);
    CHECK(*kept.predictedGain < 1.5);
    CHECK(kept.keptEqualCounts);
    CHECK(kept.stageCount == 2);
    CHECK(kept.skippedPixels == size_t(flat.pixelCount()));
    CHECK(kept.meanPilotWeight == Approx(0.05).epsilon(1e-12));
    for (int p = 0; p < flat.pixelCount(); ++p) CHECK(kept.alpha[size_t(p) * 2] == 0.51);
  }
  // Where α pays (BRDF sampling alone has no variance under a constant sky) the rule
  // predicts the gain and lets the allocation run.
  Scene constant = smallScene("constant", "uniform:1,0,1", 24, 16);
  Rendering adapted = renderWith(constant, Method::Exact, 100, 9);
  REQUIRE(adapted.predictedGain);
  CHECK(*adapted.predictedGain > 2.0);
  CHECK_FALSE(adapted.keptEqualCounts);
  // Without neighbours (--pool 0) a pixel's own samples chose its α: nothing is held out,
  // nothing is predicted, and the rule cannot apply.
  AdaptiveOptions own;
  own.costs = {1.0, 1.0};
  own.poolRadius = 0;
  Sampler sampler(testDevice(), flat,
                  samplerConfigFor(Method::Exact, Estimator::MultiSample, 100, own, flat.techniqueCount()));
  Rendering unpredicted = render(sampler, Method::Exact, own, 100, 3);
  CHECK_FALSE(unpredicted.predictedGain);
  CHECK_FALSE(unpredicted.keptEqualCounts);
}
