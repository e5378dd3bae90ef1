#pragma once
// Every sample of one pixel, kept per technique, for the estimator that needs more
// than running sums: the sample variance of [SS23] eq. 19.

#include <vector>

#include "stats/PixelStats.h"

namespace misalloc {

struct StoredSample {
  double f;                    // f(X)
  double pdf[kMaxTechniques];  // p_i(X) for every technique i
};

class PixelSamples {
 public:
  explicit PixelSamples(int techniqueCount);

  // Same contract as PixelStats::add; a rejected sample is not stored either.
  bool add(int k, double f, const double* pdfs);

  int techniqueCount() const { return stats_.techniqueCount; }
  const PixelStats& stats() const { return stats_; }
  const std::vector<StoredSample>& samples(int k) const { return samples_[k]; }

 private:
  PixelStats stats_;
  std::vector<StoredSample> samples_[kMaxTechniques];
};

// [SS23] eq. 19: the sample estimate of the multi-sample balance-heuristic variance
// V[F] = Σ_i α_i σ_i² ([SS23] eq. 3) at weights alpha. Techniques with α_i = 0 contribute
// nothing. Returns +∞ if a sample of a technique with α_i > 0 has p_α = 0 and f ≠ 0.
double mixtureSampleVariance(const PixelSamples& samples, const std::vector<double>& alpha);

}  // namespace misalloc
