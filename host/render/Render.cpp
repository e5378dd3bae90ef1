#include "render/Render.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "Error.h"
#include "Interruption.h"
#include "KernelCode.h"
#include "alloc/Apportion.h"
#include "alloc/GridSearchAllocator.h"
#include "alloc/PixelRuleAllocator.h"
#include "alloc/StageWeights.h"
#include "alloc/WholeImageRule.h"
#include "render/RunChecks.h"

namespace misalloc {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

struct StageTotals {
  std::vector<double> rgb, variance;
  double kernelSeconds = 0;
};

// A stage as it ran: its counts and its per-pixel estimates.
struct TakenStage {
  StagePlan plan;
  StageResult result;
};

// Adds a stage's estimate with each pixel's weight.
void accumulateStage(StageTotals& totals, const TakenStage& stage, Estimator estimator,
                     const std::vector<double>& weights) {
  for (size_t p = 0; p < totals.variance.size(); ++p) {
    const double w = weights[p];
    for (int c = 0; c < 3; ++c) totals.rgb[3 * p + c] += w * stage.result.rgb[3 * p + c];
    totals.variance[p] += w * w * stageVariance(stage.plan, stage.result, int(p), estimator);
  }
  totals.kernelSeconds += stage.result.kernelSeconds;
}

}  // namespace

int pilotSamples(double pilotFraction, int spp, int techniqueCount, Method method) {
  const int pilot = std::max(2 * techniqueCount, int(std::lround(pilotFraction * spp)));
  const MethodTraits& traits = methodTraits(method);
  if (!traits.adaptive() || traits.searchesWeights) {
    const int floor = kPilotSamplesPerTechnique * techniqueCount;
    return pilot < floor && 8 * floor <= spp ? floor : pilot;
  }
  const int pass = kPilotPassSamples * techniqueCount, filled = (pilot + pass - 1) / pass * pass;
  return filled <= spp / 4 ? filled : pilot;
}

std::vector<int> stageSizes(double pilotFraction, int stages, int spp, int techniqueCount, Method method) {
  if (!(pilotFraction > 0 && pilotFraction < 1))
    throw InputError(fmt::format("--pilot {}: the pilot's share of the budget must lie in (0, 1)", pilotFraction));
  if (stages < 1) throw InputError(fmt::format("--stages {}: need at least one stage after the pilot", stages));
  const int pilot = pilotSamples(pilotFraction, spp, techniqueCount, method);
  if (spp < pilot + stages)
    throw InputError(
        fmt::format("--spp {} is smaller than the pilot ({} samples: at least 2 per technique) plus {} "
                    "stage(s) of at least one sample",
                    spp, pilot, stages));
  std::vector<int> sizes{pilot};
  for (int b = 0; b < stages; ++b) sizes.push_back((spp - pilot) / stages + (b < (spp - pilot) % stages ? 1 : 0));
  return sizes;
}

namespace {

// Everything a render has sampled so far.
struct Progress {
  StageTotals totals;
  std::vector<int> taken;  // [pixel·M + k]: samples technique k took
  int samplesBefore = 0;
  std::vector<unsigned char> fellBack, floored;  // per pixel: a defensive rule was used
  std::vector<unsigned char> skipped;            // per pixel: the skip rule kept equal weights in every stage
  std::vector<unsigned char> weightsFallback;    // per pixel: OptimalWeightsFallback bits of its stages
  std::vector<StageTiming> timings;

  Progress(int pixels, int M)
      : totals{std::vector<double>(size_t(pixels) * 3, 0.0), std::vector<double>(pixels, 0.0)},
        taken(size_t(pixels) * M, 0),
        fellBack(pixels, 0),
        floored(pixels, 0),
        skipped(pixels, 0),
        weightsFallback(pixels, 0) {}
};

// Runs one stage with the given counts; the caller adds it to the estimate.
// `keepStatistics` false for the last stage, which no allocation reads. With a
// calibrated cost model, the stage's kernel time is predicted before it runs; given
// costs (--cost) predict no seconds: only their ratios are known to mean anything.
TakenStage takeStage(StageSampler& sampler, Progress& progress, std::vector<int32_t> counts, int stageSamples,
                     uint64_t seed, bool keepStatistics, const CostModel* costs,
                     std::vector<float> optimalCoefficients = {}) {
  TakenStage stage;
  stage.plan.optimalCoefficients = std::move(optimalCoefficients);
  stage.plan.techniqueCount = sampler.scene().techniqueCount();
  stage.plan.stageSamples = stageSamples;
  stage.plan.samplesBefore = progress.samplesBefore;
  stage.plan.keepStatistics = keepStatistics;
  leaveOutBackground(sampler.scene(), counts);
  stage.plan.counts = std::move(counts);
  stage.plan.firstIndex.assign(progress.taken.begin(), progress.taken.end());
  StageTiming timing;
  timing.samples = stageSamples;
  timing.keptStatistics = keepStatistics;
  const bool predicts = costs && !costs->isGiven();
  LaunchWork work;
  if (predicts) {
    work = sampler.launchWork(stage.plan);
    timing.predictedKernelSeconds = costs->predict(work);
  }
  checkInterruption();
  stage.result = sampler.run(stage.plan, seed);
  timing.kernelSeconds = stage.result.kernelSeconds;
  progress.timings.push_back(timing);
  for (size_t i = 0; i < progress.taken.size(); ++i) progress.taken[i] += stage.plan.counts[i];
  progress.samplesBefore += stageSamples;
  return stage;
}

// The next stage's counts: the stage split by the current α. Each stage is its own
// balance-heuristic estimate with its own counts, weighted w_b, so the render's
// variance is Σ_b w_b² V(α_b)/N_b ([SHS16] eq. 21 per stage): each stage is best
// split by the best α known (tests/test_staging.cpp compares it with making the
// cumulative counts approach α·N).
std::vector<int32_t> stageCounts(Progress& progress, const std::vector<Allocation>& allocations, int stageSamples) {
  const int M = int(progress.taken.size() / progress.fellBack.size());
  std::vector<int32_t> out(progress.taken.size());
#pragma omp parallel for schedule(static, 1024)
  for (size_t p = 0; p < allocations.size(); ++p) {
    int* counts = out.data() + p * M;
    apportionCounts(allocations[p].alpha.data(), M, stageSamples, counts);
    progress.fellBack[p] |= allocations[p].usedFallback() ? 1 : 0;
    progress.floored[p] |= floorCounts(counts, M) ? 1 : 0;
  }
  return out;
}

// The coefficients of the optimal weights for the next stage, split by `counts`, from
// every stage so far (alloc/OptimalWeights.h); none for the balance heuristic. The grid
// search ranked its α by the optimal weights' variance at those counts: its weights are
// solved at them too, from the samples the last stage (`last`) stored.
std::vector<float> nextCoefficients(StageSampler& sampler, Progress& progress, Method method, MisWeights weights,
                                    int poolRadius, const StagePlan& first, const StagePlan& last,
                                    const std::vector<int32_t>& counts) {
  if (weights != MisWeights::Optimal) return {};
  StageCoefficients next = methodTraits(method).searchesWeights
                               ? retargetedCoefficients(sampler, last, counts, poolRadius)
                               : optimalCoefficients(sampler, poolRadius, first, counts);
  for (size_t p = 0; p < next.fallback.size(); ++p) progress.weightsFallback[p] |= next.fallback[p];
  return std::move(next.coefficients);
}

// The pilot: every pixel splits its first stage equally.
std::vector<int32_t> equalCounts(int pixels, int M, int stageSamples) {
  return sameCountsEverywhere(pixels, apportionCounts(std::vector<double>(M, 1.0), stageSamples));
}

// The largest stage that keeps statistics (all but the last), of the stages of the
// scene's technique count M: the grid searches store its samples.
int largestStatisticsStage(Method method, const AdaptiveOptions& options, int spp, int techniqueCount) {
  std::vector<int> sizes = stageSizes(options.pilotFraction, options.stages, spp, techniqueCount, method);
  sizes.pop_back();
  return *std::max_element(sizes.begin(), sizes.end());
}

}  // namespace

SamplerConfig samplerConfigFor(Method method, Estimator fixedSplitEstimator, int spp, const AdaptiveOptions& options,
                               int techniqueCount) {
  const MethodTraits& traits = methodTraits(method);
  SamplerConfig config;
  config.estimator = traits.fixesEstimator() ? traits.estimator : fixedSplitEstimator;
  if (config.estimator == Estimator::Resampled) config.risCandidates = options.risCandidates;
  config.statsMask = traits.statistics;
  config.sampleCapacity = traits.storesSamples ? spp : 0;
  if (options.weights == MisWeights::Optimal) {
    config.optimalWeights = true;
    config.statsMask |= MA_STATS_OPTIMAL;
  }
  if (traits.searchesWeights) {
    // The grid searches keep running sums: the samples of one stage at a time are
    // stored, and the last stage stores none (the oracle's: its probe only).
    config.sampleCapacity = traits.split == Split::Probed
                                ? options.oracleSamples
                                : largestStatisticsStage(method, options, spp, techniqueCount);
    config.gridSize = options.gridSize;
    config.runningSums = traits.split == Split::Staged && options.stages > 1;
    // Rule (b) judges each α_0 by the pdf of the share it would run (WeightGrid).
    // With optimal weights the search ranks [Kon19]'s variance of the pilot's own pdfs.
    config.shareColumns = (traits.split == Split::Probed || options.gridRule == GridRule::MinCostVariance) &&
                          options.weights == MisWeights::Balance;
  }
  return config;
}

namespace {

// The allocation between the stages of `method` (alloc/StageAllocator.h), made before
// the render's clock starts: a sampler's first grid search builds its kernels and
// buffers, which are not render time, as the sampler's own are not.
std::unique_ptr<StageAllocator> makeStageAllocator(StageSampler& sampler, Method method,
                                                   const AdaptiveOptions& options) {
  const MethodTraits& traits = methodTraits(method);
  if (traits.searchesWeights) {
    // The oracle's probe stands in for the true variance: rule (b) by the pixel alone.
    const bool pooled = traits.split == Split::Staged && options.gridRule == GridRule::MinCostVariance;
    const GridRule rule = traits.split == Split::Probed ? GridRule::MinCostVariance : options.gridRule;
    const Scene& scene = sampler.scene();
    std::optional<PooledSelection> pooling;
    if (pooled) pooling = PooledSelection{scene.grid.width, scene.grid.height, options.poolRadius, options.minGain};
    return std::make_unique<GridSearchAllocator>(sampler, rule, pooling);
  }
  PixelRule rule;
  switch (method) {
    case Method::Heuristic:
      rule = PixelRule::Heuristic;
      break;
    case Method::SigmaSqrtC:
      rule = PixelRule::SigmaSqrtC;
      break;
    case Method::Linear:
      rule = PixelRule::Linear;
      break;
    default:
      throw std::logic_error("no allocation for " + methodName(method));
  }
  return std::make_unique<PixelRuleAllocator>(rule, options.poolRadius, options.linearRule);
}

}  // namespace

Rendering render(StageSampler& sampler, Method method, const AdaptiveOptions& options, int spp, uint64_t seed) {
  const Scene& scene = sampler.scene();
  const int pixels = scene.pixelCount(), M = scene.techniqueCount();
  const MethodTraits& traits = methodTraits(method);
  const Estimator estimator = sampler.config().estimator;
  requireValidRun(scene.options, method, estimator, spp, options);
  if ((options.weights == MisWeights::Optimal) != sampler.config().optimalWeights)
    throw std::logic_error("the sampler's config does not match the weights asked for (samplerConfigFor)");
  std::unique_ptr<StageAllocator> allocator;
  std::optional<CostModel> givenCosts;
  const CostModel* model = nullptr;
  if (traits.adaptive()) {
    allocator = makeStageAllocator(sampler, method, options);
    if (options.costs.empty()) {
      // The sampler's own (set from the cost cache, or calibrated at its first render),
      // found before the clock starts, as its kernels' compilation is.
      model = &sampler.costModel();
    } else {
      validateCosts(options.costs, M);
      givenCosts = CostModel::given(options.costs);
      model = &*givenCosts;
    }
  }
  auto start = Clock::now();
  sampler.reset();
  Rendering out;
  Progress progress(pixels, M);
  if (!traits.adaptive() && options.weights == MisWeights::Optimal) {
    // A fixed split has nothing to solve the optimal weights from: a pilot of the same
    // split with the balance heuristic, then the rest with the weights solved from it,
    // each stage weighted by its size.
    std::vector<int> sizes = stageSizes(options.pilotFraction, 1, spp, M, method);
    out.stageCount = 2;
    TakenStage pilot =
        takeStage(sampler, progress, singleStagePlan(scene, method, sizes[0]).counts, sizes[0], seed, true, nullptr);
    accumulateStage(progress.totals, pilot, estimator, std::vector<double>(pixels, double(sizes[0]) / spp));
    auto solveStart = Clock::now();
    std::vector<int32_t> counts = singleStagePlan(scene, method, sizes[1]).counts;
    std::vector<float> coefficients = nextCoefficients(sampler, progress, method, options.weights, options.poolRadius,
                                                       pilot.plan, pilot.plan, counts);
    out.allocationSeconds = secondsSince(solveStart);
    TakenStage rest =
        takeStage(sampler, progress, std::move(counts), sizes[1], seed, false, nullptr, std::move(coefficients));
    accumulateStage(progress.totals, rest, estimator, std::vector<double>(pixels, double(sizes[1]) / spp));
  } else if (!traits.adaptive()) {
    TakenStage stage =
        takeStage(sampler, progress, singleStagePlan(scene, method, spp).counts, spp, seed, false, nullptr);
    accumulateStage(progress.totals, stage, estimator, std::vector<double>(pixels, 1.0));
  } else if (traits.split == Split::Probed) {
    // Evaluation only: a probe of oracleSamples equal-count samples per pixel, with a
    // seed of its own, stands in for the true variance as a function of α; the render
    // then takes the α it finds best in one stage.
    auto probeStart = Clock::now();
    TakenStage probe = takeStage(sampler, progress, equalCounts(pixels, M, options.oracleSamples),
                                 options.oracleSamples, ~seed, true, model);
    std::vector<Allocation> best = allocator->allocate(sampler, model->perSample(false)).allocations;
    Progress render(pixels, M);
    render.samplesBefore = progress.samplesBefore;
    render.timings = std::move(progress.timings);
    std::vector<int32_t> counts = stageCounts(render, best, spp);
    // The probe is per pixel: the oracle's weights are solved from the pixel's own.
    std::vector<float> coefficients =
        nextCoefficients(sampler, render, method, options.weights, 0, probe.plan, probe.plan, counts);
    out.allocationSeconds = secondsSince(probeStart);
    TakenStage stage = takeStage(sampler, render, std::move(counts), spp, seed, false, model, std::move(coefficients));
    accumulateStage(render.totals, stage, estimator, std::vector<double>(pixels, 1.0));
    progress = std::move(render);
  } else {
    std::vector<int> sizes = stageSizes(options.pilotFraction, options.stages, spp, M, method);
    out.stageCount = int(sizes.size());
    std::fill(progress.skipped.begin(), progress.skipped.end(), 1);
    TakenStage pilot = takeStage(sampler, progress, equalCounts(pixels, M, sizes[0]), sizes[0], seed, true, model);
    StagePlan last = pilot.plan;  // the last stage, whose samples a grid search stored
    std::vector<double> pilotWeights;
    for (size_t b = 1; b < sizes.size(); ++b) {
      bool keepStatistics = b + 1 < sizes.size();
      auto allocationStart = Clock::now();
      // Each technique weighed by its cost in the kernel that runs the next stage.
      StageAllocation next = allocator->allocate(sampler, model->perSample(keepStatistics));
      if (b == 1) {
        out.predictedGain = predictedImageGain(next, model->perSample(false), scene.geometry.covered);
        if (keepsEqualCounts(out.predictedGain, options.imageGainBelow)) {
          // The rest of the budget in one stage at equal counts, which no allocation follows.
          out.keptEqualCounts = true;
          next = equalStageAllocation(pixels, M);
          sizes = {sizes[0], spp - sizes[0]};
          out.stageCount = 2;
          keepStatistics = false;
        }
      }
      for (int p = 0; p < pixels; ++p) progress.skipped[p] &= next.skipped[p];
      std::vector<int32_t> counts = stageCounts(progress, next.allocations, sizes[b]);
      std::vector<float> coefficients =
          nextCoefficients(sampler, progress, method, options.weights, options.poolRadius, pilot.plan, last, counts);
      out.allocationSeconds += secondsSince(allocationStart);
      if (b == 1) {
        pilotWeights.resize(pixels);
        for (int p = 0; p < pixels; ++p) pilotWeights[p] = pilotWeight(next.varianceRatio[p], sizes[0], spp);
        accumulateStage(progress.totals, pilot, estimator, pilotWeights);
      }
      TakenStage stage = takeStage(sampler, progress, std::move(counts), sizes[b], seed, keepStatistics, model,
                                   std::move(coefficients));
      last = stage.plan;
      // The stages after the pilot share the rest of the weight by their sizes.
      std::vector<double> weights(pixels);
      for (int p = 0; p < pixels; ++p) weights[p] = (1 - pilotWeights[p]) * sizes[b] / double(spp - sizes[0]);
      accumulateStage(progress.totals, stage, estimator, weights);
    }
    out.meanPilotWeight = std::accumulate(pilotWeights.begin(), pilotWeights.end(), 0.0) / pixels;
  }
  // The background's sums are empty: whatever the rules made of them is not reported.
  const std::vector<unsigned char>& covered = scene.geometry.covered;
  for (auto* flags : {&progress.fellBack, &progress.floored, &progress.skipped, &progress.weightsFallback})
    for (int p = 0; p < pixels; ++p) (*flags)[p] &= covered[p] ? 0xff : 0;
  out.fallbackPixels = size_t(std::count(progress.fellBack.begin(), progress.fellBack.end(), 1));
  out.flooredPixels = size_t(std::count(progress.floored.begin(), progress.floored.end(), 1));
  out.skippedPixels = size_t(std::count(progress.skipped.begin(), progress.skipped.end(), 1));
  out.weightsFallbacks = countWeightsFallbacks(progress.weightsFallback);
  out.image =
      RgbImage{scene.grid.width, scene.grid.height,
               std::vector<float>(progress.totals.rgb.begin(), progress.totals.rgb.end()), scene.geometry.alpha()};
  out.variance = std::move(progress.totals.variance);
  out.alpha.resize(progress.taken.size());
  for (size_t i = 0; i < progress.taken.size(); ++i) out.alpha[i] = double(progress.taken[i]) / spp;
  out.statisticsBytesPerPixel = double(sampler.statSlots()) * sizeof(double) +
                                double(sampler.storedSampleCount()) * sizeof(float) / pixels +
                                double(allocator ? allocator->bytesPerPixel() : 0);
  out.kernelSeconds = progress.totals.kernelSeconds;
  out.stages = std::move(progress.timings);
  if (model) out.costModel = *model;
  out.devices = sampler.deviceShares();
  out.imbalanceSeconds = sampler.imbalanceSeconds();
  out.wallSeconds = secondsSince(start);
  out.hostSeconds = std::max(0.0, out.wallSeconds - out.kernelSeconds - out.allocationSeconds);
  return out;
}

}  // namespace misalloc
