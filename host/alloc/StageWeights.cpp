#include "alloc/StageWeights.h"

#include <cmath>

#include "stats/PixelStats.h"

namespace misalloc {

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

double pilotWeight(float varianceRatio, int pilotSamples, int spp) {
  const double r = std::isnan(varianceRatio) ? 1.0 : double(varianceRatio);
  return pilotSamples / (pilotSamples + (spp - pilotSamples) * r);
}

}  // namespace misalloc
