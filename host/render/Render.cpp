#include "render/Render.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "Error.h"
#include "alloc/Apportion.h"
#include "alloc/HeuristicAllocation.h"
#include "alloc/SigmaAllocation.h"
#include "render/RunningStats.h"

namespace misalloc {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// One pixel's weights for the next stage, from its samples so far.
Allocation allocatePixel(Method method, const AdaptiveOptions& options, const PixelStats& stats,
                         const PixelSamples* samples) {
  switch (method) {
    case Method::Heuristic:
      return allocateHeuristic(stats, options.costs);  // 000 eq. 4.20
    case Method::SigmaSqrtC:
      return allocateSigmaSqrtC(stats, options.costs);  // 002 eq. 31
    case Method::Linear:
      return allocateLinear(*samples, options.linearRule);  // 003 eq. 14
    default:
      throw std::logic_error("no per-pixel rule for " + methodName(method));
  }
}

// Every technique takes at least one sample of each stage where a stage could be
// biased without: the count-independent estimator (002 eq. 26) needs a sample of each
// technique for all its terms, and with the BRDF split into lobes the specular lobe
// alone does not cover the diffuse lobe's support. (With M = 2 either technique alone
// covers the whole integrand.) True if it changed the counts.
bool floorCounts(std::vector<int>& counts) {
  bool changed = false;
  for (int& n : counts) {
    if (n > 0) continue;
    auto largest = std::max_element(counts.begin(), counts.end());
    if (*largest <= 1) break;
    --*largest;
    n = 1;
    changed = true;
  }
  return changed;
}

struct StageTotals {
  std::vector<double> rgb, variance;
  double kernelSeconds = 0;
};

// Adds a stage's estimate with its fixed weight N_b/N.
void accumulateStage(StageTotals& totals, const StagePlan& plan, const StageResult& stage, Estimator estimator,
                     double weight) {
  for (size_t i = 0; i < totals.rgb.size(); ++i) totals.rgb[i] += weight * stage.rgb[i];
  for (size_t p = 0; p < totals.variance.size(); ++p)
    totals.variance[p] += weight * weight * stageVariance(plan, stage, int(p), estimator);
  totals.kernelSeconds += stage.kernelSeconds;
}

}  // namespace

std::vector<int> stageSizes(double pilotFraction, int stages, int spp, int techniqueCount) {
  if (!(pilotFraction > 0 && pilotFraction < 1))
    throw InputError(fmt::format("--pilot {}: the pilot's share of the budget must lie in (0, 1)", pilotFraction));
  if (stages < 1) throw InputError(fmt::format("--stages {}: need at least one stage after the pilot", stages));
  int pilot = std::max(2 * techniqueCount, int(std::lround(pilotFraction * spp)));
  if (spp < pilot + stages)
    throw InputError(
        fmt::format("--spp {} is smaller than the pilot ({} samples: at least 2 per technique) plus {} "
                    "stage(s) of at least one sample",
                    spp, pilot, stages));
  std::vector<int> sizes{pilot};
  for (int b = 0; b < stages; ++b) sizes.push_back((spp - pilot) / stages + (b < (spp - pilot) % stages ? 1 : 0));
  return sizes;
}

SamplerConfig samplerConfigFor(Method method, Estimator fixedSplitEstimator, int spp) {
  SamplerConfig config;
  config.estimator = isAdaptive(method) ? methodEstimator(method) : fixedSplitEstimator;
  config.statsMask = methodStatistics(method);
  config.sampleCapacity = methodStoresSamples(method) ? spp : 0;
  return config;
}

double stageVariance(const StagePlan& plan, const StageResult& result, int pixel, Estimator estimator) {
  const int M = plan.techniqueCount;
  const double N = plan.stageSamples;
  const double* m = result.moments.data() + size_t(pixel) * M * 2;
  const int* counts = plan.counts.data() + size_t(pixel) * M;
  if (estimator == Estimator::OneSample) {
    double sum = 0, sumSquares = 0;
    for (int k = 0; k < M; ++k) sum += m[2 * k], sumSquares += m[2 * k + 1];
    return sampleVariance(sum, sumSquares, N) / N;
  }
  double v = 0;
  for (int k = 0; k < M; ++k) {
    double n = counts[k];
    if (n == 0) continue;
    double s2 = sampleVariance(m[2 * k], m[2 * k + 1], n);
    v += estimator == Estimator::CountIndependent ? s2 / n : n * s2 / (N * N);
  }
  return v;
}

Rendering render(StageSampler& sampler, Method method, const AdaptiveOptions& options, int spp, uint64_t seed) {
  auto start = Clock::now();
  const Scene& scene = sampler.scene();
  const int pixels = scene.pixelCount(), M = scene.techniqueCount();
  const Estimator estimator = sampler.config().estimator;
  Rendering out;
  StageTotals totals{std::vector<double>(size_t(pixels) * 3, 0.0), std::vector<double>(pixels, 0.0)};
  std::vector<int> taken(size_t(pixels) * M, 0);

  if (!isAdaptive(method)) {
    StagePlan plan = singleStagePlan(scene, method, spp);
    accumulateStage(totals, plan, sampler.run(plan, seed), estimator, 1.0);
    taken.assign(plan.counts.begin(), plan.counts.end());
  } else {
    validateCosts(options.costs, M);
    std::vector<int> sizes = stageSizes(options.pilotFraction, options.stages, spp, M);
    out.stageCount = int(sizes.size());
    std::vector<unsigned char> fellBack(pixels, 0), floored(pixels, 0);
    int samplesBefore = 0;
    for (size_t b = 0; b < sizes.size(); ++b) {
      StagePlan plan;
      plan.techniqueCount = M;
      plan.stageSamples = sizes[b];
      plan.samplesBefore = samplesBefore;
      plan.counts.resize(size_t(pixels) * M);
      plan.firstIndex.assign(taken.begin(), taken.end());
      auto allocationStart = Clock::now();
      std::vector<double> stats = b > 0 ? sampler.statistics() : std::vector<double>{};
      std::vector<float> stored = b > 0 && methodStoresSamples(method) ? sampler.storedSamples() : std::vector<float>{};
      const int slots = sampler.statSlots();
#pragma omp parallel for schedule(dynamic, 256)
      for (int p = 0; p < pixels; ++p) {
        std::vector<int> pixelTaken(taken.begin() + size_t(p) * M, taken.begin() + size_t(p + 1) * M);
        std::vector<int> counts;
        if (b == 0) {
          counts = apportionCounts(std::vector<double>(M, 1.0), sizes[0]);
        } else {
          PixelStats pixelStats = decodePixelStats(stats.data() + size_t(p) * slots, sampler.config().statsMask, M);
          std::optional<PixelSamples> samples;
          if (!stored.empty())
            samples = decodePixelSamples(stored, p, samplesBefore, sampler.config().sampleCapacity, M);
          Allocation a = allocatePixel(method, options, pixelStats, samples ? &*samples : nullptr);
          fellBack[p] |= a.usedFallback() ? 1 : 0;
          counts = nextStageCounts(pixelTaken, a.alpha, samplesBefore + sizes[b]);
        }
        if (estimator == Estimator::CountIndependent || M > 2) floored[p] |= floorCounts(counts) ? 1 : 0;
        std::copy(counts.begin(), counts.end(), plan.counts.begin() + size_t(p) * M);
      }
      out.allocationSeconds += secondsSince(allocationStart);
      StageResult stage = sampler.run(plan, seed);
      // Stage b's estimate is unbiased given the earlier stages, whatever its counts;
      // weights N_b/N fixed in advance keep the combination unbiased.
      accumulateStage(totals, plan, stage, estimator, double(sizes[b]) / spp);
      for (size_t i = 0; i < taken.size(); ++i) taken[i] += plan.counts[i];
      samplesBefore += sizes[b];
    }
    out.fallbackPixels = size_t(std::count(fellBack.begin(), fellBack.end(), 1));
    out.flooredPixels = size_t(std::count(floored.begin(), floored.end(), 1));
  }
  out.image = RgbImage{scene.grid.width, scene.grid.height, std::vector<float>(totals.rgb.begin(), totals.rgb.end())};
  out.variance = std::move(totals.variance);
  out.alpha.resize(taken.size());
  for (size_t i = 0; i < taken.size(); ++i) out.alpha[i] = double(taken[i]) / spp;
  out.kernelSeconds = totals.kernelSeconds;
  out.wallSeconds = secondsSince(start);
  out.hostSeconds = std::max(0.0, out.wallSeconds - out.kernelSeconds - out.allocationSeconds);
  return out;
}

}  // namespace misalloc
