// The cost model (sampling/CostModel.h): the work a launch does as its work-groups run
// it (sampling/LaunchWork.h), the fit on synthetic timing tables with a known answer,
// the calibration and per-stage predictions of a real render, and the cost cache
// (render/CostCache.h) that makes the renders that allocate with it repeatable.
#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "CliRunner.h"
#include "SafetyWorkspace.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "render/CostCache.h"
#include "render/Render.h"
#include "sampling/CostModel.h"
#include "sampling/HostSampler.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

StagePlan planOf(const std::vector<std::vector<int>>& counts, bool keepStatistics = false) {
  StagePlan plan;
  plan.techniqueCount = int(counts.front().size());
  plan.keepStatistics = keepStatistics;
  for (int n : counts.front()) plan.stageSamples += n;
  for (const auto& pixel : counts) plan.counts.insert(plan.counts.end(), pixel.begin(), pixel.end());
  plan.firstIndex.assign(plan.counts.size(), 0u);
  return plan;
}

// The C++ reference, keeping every plan it is asked to run.
struct PlanRecorder final : HostSampler {
  using HostSampler::HostSampler;
  std::vector<StagePlan> plans;
  StageResult runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) override {
    plans.push_back(plan);
    return HostSampler::runPixels(plan, seed, firstSlot, range);
  }
};

LaunchWork work(std::vector<double> slots, bool keepsStatistics = false) { return {keepsStatistics, std::move(slots)}; }

// T = t_0 + Σ_k c_k S_k, exactly.
double launchSeconds(double perLaunch, const std::vector<double>& perSample, const LaunchWork& w) {
  double t = perLaunch;
  for (size_t k = 0; k < perSample.size(); ++k) t += perSample[k] * w.slots[k];
  return t;
}

}  // namespace

TEST_CASE("a launch's work is each work-group's largest count per technique", "[costmodel]") {
  // Sorted by n_0: (1,3) (2,2) | (3,1) (3,1); groups of two run (2,3) and (3,1).
  const StagePlan plan = planOf({{3, 1}, {1, 3}, {2, 2}, {3, 1}}, true);
  const LaunchWork grouped = launchWork(plan, Estimator::MultiSample, 2);
  CHECK(grouped.keepsStatistics);
  CHECK(grouped.slots == std::vector<double>{2 * 2 + 2 * 3, 2 * 3 + 2 * 1});
  // A sampler that runs each pixel alone, and the one-sample estimator's single pass,
  // do the counts.
  CHECK(launchWork(plan, Estimator::MultiSample, 1).slots == std::vector<double>{9, 7});
  CHECK(launchWork(plan, Estimator::OneSample, 8).slots == std::vector<double>{9, 7});
  // The last group's padding work-items repeat a pixel of the group: no extra work.
  CHECK(launchWork(planOf({{4, 0}, {1, 3}, {2, 2}}), Estimator::MultiSample, 2).slots ==
        std::vector<double>{2 * 2 + 2 * 4, 2 * 3 + 2 * 0});
  // Of three techniques, a group whose n_1 are all 0 still runs technique 1's loop once;
  // the first and the last technique's loops run no turn at 0 (docs/pocl.md, rule 12).
  CHECK(launchWork(planOf({{0, 0, 4}, {3, 0, 1}}), Estimator::MultiSample, 2).slots ==
        std::vector<double>{2 * 3, 2 * 1, 2 * 4});
}

TEST_CASE("a launch leaves out the pixels that take no samples", "[costmodel]") {
  // Pixels 1 and 3 take none (the background): the launch runs pixels 2 and 0, one group
  // of three that runs (3, 3), not the groups (1, 3, 2) and (0) that run (1, 3) and (3, 1).
  const StagePlan plan = planOf({{3, 1}, {0, 0}, {1, 3}, {0, 0}}, true);
  CHECK(coherentPixelOrder(plan, {0, 4}) == std::vector<int32_t>{2, 0});
  CHECK(coherentPixelOrder(plan, {1, 2}).empty());
  CHECK(launchWork(plan, Estimator::MultiSample, 3).slots == std::vector<double>{3 * 3, 3 * 3});
}

// A calibration that also sampled the background fitted its fixed cost to pixels that
// renders leave out of their launches: its launches take the covered pixels only.
TEST_CASE("the calibration launches the pixels a render launches and not the background", "[costmodel]") {
  Scene scene = smallScene("forest_slope", "seed000", 24, 16);
  giveBackground(scene, 5);
  PlanRecorder sampler(scene);
  calibrateCostModel(sampler);
  REQUIRE(sampler.plans.size() > 1);
  size_t background = 0, coveredLeftOut = 0;
  for (const StagePlan& plan : sampler.plans)
    for (int p = 0; p < scene.pixelCount(); ++p) {
      const bool takes = takesSamples(plan, p);
      if (scene.geometry.covered[size_t(p)])
        coveredLeftOut += !takes;
      else
        background += takes;
    }
  CHECK(background == 0);
  CHECK(coveredLeftOut == 0);
}

namespace {

// Launch times T = t_0 + Σ_k c_k S_k, each off by up to ±`noise` of itself, without
// sampling: a CPU, whose lanes take a pixel's samples 16 at a time, whose costs the
// calibration should find.
struct SyntheticTimes final : HostSampler {
  SyntheticTimes(const Scene& scene, double perLaunch, std::vector<double> perSample, double noise)
      : HostSampler(scene), perLaunch(perLaunch), perSample(std::move(perSample)), noise(noise) {}
  double perLaunch;
  std::vector<double> perSample;
  double noise;
  std::mt19937 random{7};
  int pixelLanes(bool) const override { return 16; }
  StageResult runPixels(const StagePlan& plan, uint64_t, int, PixelRange) override {
    StageResult result;
    result.kernelSeconds = launchSeconds(perLaunch, perSample, launchWork(plan)) *
                           (1 + std::uniform_real_distribution<double>(-noise, noise)(random));
    return result;
  }
};

}  // namespace

TEST_CASE("the calibration finds each technique's cost where every launch's fixed time dominates", "[costmodel]") {
  // The optimal pdf per pixel builds each pixel's table in every launch: at 256x256,
  // 35 ms a launch against 1–1.5 ms for a sample of one technique on every pixel, and
  // launch times that move by a few percent. Calibrated on launches of one and four
  // samples per technique, one pass of the lanes either way, the costs were noise (one
  // came out 8x too cheap).
  const Scene scene = smallScene("forest_slope", "seed000", 16, 16);
  const std::vector<double> costs{4.5e-6, 3e-6};  // per sample slot: 1.2 and 0.8 ms a sample per pixel
  // Within 10 % at ±5 % noise: the new sizes stayed within 7.3 % over 20 noise seeds,
  // the old ones missed it for 12 of the 40 costs (docs/testing.md).
  for (double noise : {0.0, 0.05}) {
    SyntheticTimes machine(scene, 0.035, costs, noise);
    const CostModel model = calibrateCostModel(machine);
    for (int k = 0; k < 2; ++k) {
      INFO("noise " << noise << ", technique " << k << ": " << model.perSample(false)[size_t(k)] << " s");
      CHECK(model.perSample(false)[size_t(k)] == Approx(costs[size_t(k)]).epsilon(noise > 0 ? 0.1 : 1e-6));
    }
  }
}

TEST_CASE("one pixel per work-group runs each count rounded up to the lanes", "[costmodel]") {
  // Lanes of 4: 9 → 12, 7 → 8, 0 → 0, 16 → 16; the group size does not matter.
  const StagePlan plan = planOf({{9, 7}, {0, 16}});
  CHECK(launchWork(plan, Estimator::MultiSample, 8, 4).slots == std::vector<double>{12 + 0, 8 + 16});
  // A technique between the first and the last runs one pass at 0; a pixel that takes
  // no samples is not launched.
  CHECK(launchWork(planOf({{5, 0, 3}, {0, 0, 0}}), Estimator::MultiSample, 8, 4).slots ==
        std::vector<double>{8, 4, 4});
  // One-sample: N = 16 is a whole pass of lanes, shared by the counts' expectation;
  // N = 5 rounds up to 8.
  CHECK(launchWork(plan, Estimator::OneSample, 8, 4).slots == std::vector<double>{9, 23});
  CHECK(launchWork(planOf({{3, 2}, {1, 4}}), Estimator::OneSample, 8, 4).slots ==
        std::vector<double>{8.0 * 3 / 5 + 8.0 * 1 / 5, 8.0 * 2 / 5 + 8.0 * 4 / 5});
}

TEST_CASE("the cost model recovers the costs of a synthetic timing table", "[costmodel]") {
  const double t0 = 2e-3;
  const std::vector<double> c{7.5e-8, 2.5e-8, 4e-8};
  CostModel model(3);
  for (const LaunchWork& w : {work({1e5, 0, 0}), work({4e5, 0, 0}), work({0, 1e5, 0}), work({0, 4e5, 0}),
                              work({0, 0, 2e5}), work({1e5, 1e5, 1e5})})
    model.observe(w, launchSeconds(t0, c, w));
  CHECK(model.launchCount(false) == 6);
  CHECK(model.perLaunch(false) == Approx(t0).epsilon(1e-9));
  for (int k = 0; k < 3; ++k) CHECK(model.perSample(false)[k] == Approx(c[k]).epsilon(1e-9));
  const LaunchWork unseen = work({3e6, 1e6, 5e5});
  CHECK(model.predict(unseen) == Approx(launchSeconds(t0, c, unseen)).epsilon(1e-9));
  // The other kernel has seen nothing: its fit is its own.
  CHECK(model.launchCount(true) == 0);
  CHECK(model.predict(work({1e5, 1e5, 1e5}, true)) == 0);
}

TEST_CASE("the fit keeps every cost positive", "[costmodel]") {
  SECTION("an intercept below zero leaves the fit") {
    // Launches that take less than their samples' share: t_0 < 0 fits them best.
    CostModel model(2);
    for (const LaunchWork& w : {work({1e5, 0}), work({4e5, 0}), work({0, 1e5}), work({0, 4e5})})
      model.observe(w, launchSeconds(-1e-3, {5e-8, 2e-8}, w));
    CHECK(model.perLaunch(false) == 0);
    CHECK(model.perSample(false)[0] > 0);
    CHECK(model.perSample(false)[1] > 0);
  }
  SECTION("a technique that seems to save time costs what the cheapest does") {
    CostModel model(2);
    for (const LaunchWork& w : {work({1e5, 0}), work({4e5, 0}), work({1e5, 1e5}), work({1e5, 4e5})})
      model.observe(w, launchSeconds(1e-3, {5e-8, -1e-9}, w));
    CHECK(model.perSample(false)[1] == model.perSample(false)[0]);
    CHECK(model.perSample(false)[0] > 0);
  }
  SECTION("launches whose time does not grow with their samples") {
    // A tiny image on a fast device: t_0 alone fits, every c_k within the noise of 0.
    CostModel model(2);
    const double seconds[] = {1.0e-3, 0.99e-3, 1.0e-3, 0.99e-3, 0.995e-3};
    const LaunchWork shapes[] = {work({16, 0}), work({64, 0}), work({0, 16}), work({0, 64}), work({16, 16})};
    for (int i = 0; i < 5; ++i) model.observe(shapes[i], seconds[i]);
    CHECK(model.perLaunch(false) == 0);
    CHECK(model.perSample(false)[0] > 0);
    CHECK(model.perSample(false)[1] > 0);
  }
  SECTION("with no launch to spare, no intercept") {
    CostModel model(2);
    model.observe(work({1e5, 0}), 0.01);
    model.observe(work({0, 1e5}), 0.002);
    CHECK(model.perLaunch(false) == 0);
    CHECK(model.perSample(false)[0] == Approx(1e-7));
    CHECK(model.perSample(false)[1] == Approx(2e-8));
  }
}

TEST_CASE("given costs are used as given", "[costmodel]") {
  CostModel model = CostModel::given({3e-8, 1e-8});
  model.observe(work({1e5, 1e5}), 1.0);
  CHECK(model.isGiven());
  CHECK(model.perLaunch(false) == 0);
  CHECK(model.perSample(true) == std::vector<double>{3e-8, 1e-8});
  CHECK(model.predict(work({1e5, 2e5})) == Approx(5e-3));
}

TEST_CASE("a render calibrates its sampler's model and predicts every stage", "[costmodel]") {
  const Scene scene = smallScene("cosk:4", "seed000", 64, 64);
  AdaptiveOptions options;
  options.stages = 2;
  const int spp = 64;
  Sampler sampler(testDevice(), scene,
                  samplerConfigFor(Method::Exact, Estimator::MultiSample, spp, options, scene.techniqueCount()));
  const Rendering r = render(sampler, Method::Exact, options, spp, 1);
  REQUIRE(r.costModel);
  CHECK_FALSE(r.costModel->isGiven());
  for (bool statistics : {false, true}) {
    // Both kernels calibrated on 2M + 1 shapes.
    CHECK(r.costModel->launchCount(statistics) == 2 * scene.techniqueCount() + 1);
    for (double c : r.costModel->perSample(statistics)) CHECK(c > 0);
  }
  REQUIRE(r.stages.size() == 3);
  CHECK(r.stages[0].keptStatistics);
  CHECK_FALSE(r.stages[2].keptStatistics);
  int samples = 0;
  for (const StageTiming& t : r.stages) {
    REQUIRE(t.predictedKernelSeconds);
    CHECK(*t.predictedKernelSeconds > 0);
    CHECK(t.kernelSeconds > 0);
    samples += t.samples;
  }
  CHECK(samples == spp);

  SECTION("a second render predicts with the same model: calibrated once, never refitted") {
    const CostModel before = sampler.costModel();
    const Rendering again = render(sampler, Method::Exact, options, spp, 2);
    for (bool statistics : {false, true}) {
      CHECK(again.costModel->launchCount(statistics) == before.launchCount(statistics));
      CHECK(again.costModel->perSample(statistics) == before.perSample(statistics));
      CHECK(again.costModel->perLaunch(statistics) == before.perLaunch(statistics));
    }
  }
}

TEST_CASE("fixed splits are timed but not predicted", "[costmodel]") {
  const Scene scene = smallScene("cosk:4", "seed000", 32, 32);
  AdaptiveOptions options;
  Sampler sampler(testDevice(), scene,
                  samplerConfigFor(Method::Equal, Estimator::MultiSample, 16, options, scene.techniqueCount()));
  const Rendering r = render(sampler, Method::Equal, options, 16, 1);
  REQUIRE(r.stages.size() == 1);
  CHECK_FALSE(r.stages[0].predictedKernelSeconds);
  CHECK_FALSE(r.costModel);
}

namespace {

bool sameCosts(const CostModel& a, const CostModel& b) {
  for (bool statistics : {false, true})
    if (a.perSample(statistics) != b.perSample(statistics) || a.perLaunch(statistics) != b.perLaunch(statistics) ||
        a.launchCount(statistics) != b.launchCount(statistics))
      return false;
  return true;
}

}  // namespace

TEST_CASE("the cost cache calibrates a sampler once and hands every later one the same model", "[costmodel]") {
  TempDir dir("cost_cache");
  const std::string cache = (dir.path / "cache").string();
  const Scene scene = smallScene("cosk:4", "seed000", 32, 32);
  AdaptiveOptions options;
  const SamplerConfig config =
      samplerConfigFor(Method::Exact, Estimator::MultiSample, 32, options, scene.techniqueCount());
  Sampler first(testDevice(), scene, config);
  provideCostModel(first, scene, {cache, false});
  CHECK(first.costModel().source() == CostSource::Calibrated);
  const std::string path = costCachePath(cache, costCacheKey(first, scene));
  REQUIRE(std::filesystem::is_regular_file(path));

  Sampler second(testDevice(), scene, config);
  provideCostModel(second, scene, {cache, false});
  CHECK(second.costModel().source() == CostSource::Cached);
  CHECK(sameCosts(first.costModel(), second.costModel()));

  SECTION("renders with the cached model are one image, bit for bit") {
    const Rendering a = render(first, Method::Exact, options, 32, 7), b = render(second, Method::Exact, options, 32, 7);
    CHECK(a.image.rgb == b.image.rgb);
    CHECK(a.alpha == b.alpha);
  }
  SECTION("measure calibrates again and replaces the entry") {
    const std::string before = readText(path);
    Sampler third(testDevice(), scene, config);
    provideCostModel(third, scene, {cache, true});
    CHECK(third.costModel().source() == CostSource::Calibrated);
    // Two calibrations' timings agree to the last bit only by chance.
    CHECK(readText(path) != before);
    Sampler fourth(testDevice(), scene, config);
    provideCostModel(fourth, scene, {cache, false});
    CHECK(sameCosts(third.costModel(), fourth.costModel()));
  }
  SECTION("a damaged entry is calibrated again and replaced, never used") {
    std::string text = readText(path);
    const size_t digit = text.find_first_of("123456789", text.find("per_sample_s"));
    REQUIRE(digit != std::string::npos);
    text[digit] = text[digit] == '9' ? '1' : char(text[digit] + 1);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
    Sampler third(testDevice(), scene, config);
    provideCostModel(third, scene, {cache, false});
    CHECK(third.costModel().source() == CostSource::Calibrated);
    Sampler fourth(testDevice(), scene, config);
    provideCostModel(fourth, scene, {cache, false});
    CHECK(fourth.costModel().source() == CostSource::Cached);
    CHECK(sameCosts(third.costModel(), fourth.costModel()));
  }
  SECTION("an entry that is not a regular file is replaced, never opened") {
    std::filesystem::remove(path);
    REQUIRE(mkfifo(path.c_str(), 0600) == 0);  // opening a FIFO to read would block
    Sampler third(testDevice(), scene, config);
    provideCostModel(third, scene, {cache, false});
    CHECK(third.costModel().source() == CostSource::Calibrated);
    CHECK(std::filesystem::is_regular_file(path));
  }
  SECTION("another map, config or kernel build is another entry") {
    const Scene other = smallScene("cosk:2", "seed000", 32, 32);
    Sampler onOther(testDevice(), other, config);
    CHECK(costCacheKey(onOther, other) != costCacheKey(first, scene));
    Sampler heuristic(testDevice(), scene,
                      samplerConfigFor(Method::Heuristic, Estimator::MultiSample, 32, options, scene.techniqueCount()));
    CHECK(costCacheKey(heuristic, scene) != costCacheKey(first, scene));
    HostSampler host(scene, config);
    CHECK(costCacheKey(host, scene) != costCacheKey(first, scene));
  }
}

TEST_CASE("a cost cache that cannot be written leaves the render its own calibration", "[costmodel]") {
  TempDir dir("cost_cache_file");
  const std::string blocked = (dir.path / "not-a-folder").string();
  std::ofstream(blocked) << "a file where the cache's folder would be";
  const Scene scene = smallScene("cosk:4", "seed000", 16, 16);
  Sampler sampler(
      testDevice(), scene,
      samplerConfigFor(Method::Exact, Estimator::MultiSample, 32, AdaptiveOptions{}, scene.techniqueCount()));
  provideCostModel(sampler, scene, {blocked, false});
  CHECK(sampler.costModel().source() == CostSource::Calibrated);
  CHECK(std::filesystem::is_regular_file(blocked));
}
