// The error against a sampled reference, corrected for the reference's own variance,
// measures the error against the true image: checked where the true image is known,
// [HS14] eq. 6.17 (cosk:K seen along the normal), against a deliberately noisy reference.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cmath>

#include "BiasCheck.h"
#include "Error.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "render/Reference.h"
#include "report/ImageMetrics.h"

using namespace misalloc;
using namespace misalloc::test;

TEST_CASE("the reference-corrected error agrees with the error against the exact image, and the raw one does not",
          "[reference][corrected]") {
  // 64 spp on 64 × 64 pixels: a bias of 25 % in the corrected MSE; the raw one is off by ~100 %.
  BiasFamily family(0.25, 2);
  for (double K : {1.0, 3.0}) {
    const Scene scene = smallScene(fmt::format("cosk:{}", K), "seed000", 64, 64);
    const RgbImage exact = *analyticReference(scene);
    Sampler sampler(testDevice(), scene, {Estimator::MultiSample, 0, 0});
    // A reference with as many samples as the render: its own variance is about the
    // render's error, so the raw error is about twice the true one.
    SampledReference noisy = sampleReference(sampler, scene, 64, 0x8000000000000001ull);
    RgbImage render{scene.grid.width, scene.grid.height, {}};
    StageResult stage = sampler.run(singleStagePlan(scene, Method::Equal, 64), 5);
    render.rgb.assign(stage.rgb.begin(), stage.rgb.end());

    const double trueMse = std::pow(rmse(render, exact), 2);
    const CorrectedMse corrected = correctedMse(render, noisy.image, noisy.standardError);
    const double raw = std::pow(rmse(render, noisy.image), 2);
    family.add(fmt::format("K {}: corrected MSE against the true MSE", K), corrected.mse, trueMse,
               corrected.standardError);
    // The raw error, which counts the reference's variance too, lies far past the bound.
    const double zRaw = (raw - trueMse) / corrected.standardError;
    INFO(fmt::format("K {}: true MSE {:.4g}, raw {:.4g} (z {:.1f})", K, trueMse, raw, zRaw));
    CHECK(zRaw > 2 * family.bound());
    // Against the exact reference (no variance) the corrected error is the raw one.
    CHECK(correctedMse(render, exact, {}).mse == Approx(trueMse).epsilon(1e-12));
  }
  checkFamily(family);
}

TEST_CASE("a sampled reference estimates its own variance from independent batches", "[reference][corrected]") {
  // The batches' spread estimates Var(r) without bias: on a uniform grid, each pixel's
  // estimate s² and its squared error (r − I)² against the closed form are both
  // unbiased for Var(r), so the mean of s² is tested against that of (r − I)², with the
  // error of their difference per pixel (the two share the pixel's samples).
  const Scene scene = smallScene("cosk:1", "uniform:0.5,0.5,5", 32, 32);
  Sampler sampler(testDevice(), scene, {Estimator::MultiSample, 0, 0});
  SampledReference r = sampleReference(sampler, scene, 64, 0x8000000000000002ull);
  const double expected = closedForm(0.5, 0.5, 5, 1);
  std::vector<double> difference;  // per pixel, channel R: s² − (r − I)², a luminance-like rgb triple
  double squaredError = 0;
  for (size_t i = 0; i < r.image.rgb.size(); i += 3) {
    const double e2 = std::pow(r.image.rgb[i] - expected, 2);
    const double d = std::pow(r.standardError[i], 2) - e2;
    squaredError += e2 / double(r.image.rgb.size() / 3);
    difference.insert(difference.end(), {d, d, d});
  }
  const MeanAndError mean = pixelMean(difference);
  // 1024 pixels of 64 spp: a bias of 25 % in the estimated variance.
  BiasFamily family(0.25, 1);
  family.add("the batches' s² against (r − I)²", squaredError + mean.mean, squaredError, mean.standardError);
  checkFamily(family);
  CHECK_THROWS_AS(sampleReference(sampler, scene, 3, 1), InputError);
}
