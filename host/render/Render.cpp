#include "render/Render.h"

#include <chrono>

namespace misalloc {
namespace {

// Unbiased sample variance from Σ w, Σ w² over n values; 0 when n < 2.
double sampleVariance(double sum, double sumSquares, double n) {
  if (n < 2) return 0;
  return std::max(0.0, (sumSquares - sum * sum / n) / (n - 1));
}

}  // namespace

double stageVariance(const StagePlan& plan, const StageResult& result, int pixel, Estimator estimator) {
  const int M = plan.techniqueCount;
  const double N = plan.stageSamples;
  const double* m = result.moments.data() + size_t(pixel) * M * 2;
  if (estimator == Estimator::OneSample) {
    double sum = 0, sumSquares = 0;
    for (int k = 0; k < M; ++k) sum += m[2 * k], sumSquares += m[2 * k + 1];
    return sampleVariance(sum, sumSquares, N) / N;
  }
  double v = 0;
  for (int k = 0; k < M; ++k) {
    double n = plan.counts[size_t(pixel) * M + k];
    v += n * sampleVariance(m[2 * k], m[2 * k + 1], n);
  }
  return v / (N * N);
}

Rendering render(StageSampler& sampler, const Scene& scene, Method method, Estimator estimator, int spp,
                 uint64_t seed) {
  auto start = std::chrono::steady_clock::now();
  StagePlan plan = singleStagePlan(scene, method, spp);
  StageResult stage = sampler.run(plan, seed);
  Rendering out;
  const int pixels = scene.pixelCount();
  out.image.width = scene.grid.width;
  out.image.height = scene.grid.height;
  out.image.rgb.assign(stage.rgb.begin(), stage.rgb.end());
  out.variance.resize(pixels);
  for (int p = 0; p < pixels; ++p) out.variance[p] = stageVariance(plan, stage, p, estimator);
  out.kernelSeconds = stage.kernelSeconds;
  out.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.hostSeconds = std::max(0.0, out.wallSeconds - out.kernelSeconds);
  return out;
}

}  // namespace misalloc
