#pragma once
#include <cstdint>
#include <vector>

namespace misalloc {

enum class Estimator { MultiSample, OneSample };

// What one sampling stage takes per pixel: counts n_k (multi-sample; for the
// one-sample estimator they give the selection probabilities α_k = n_k/N) and the
// index of each technique's first sample, which keys its random numbers so that
// later stages never reuse an earlier stage's.
struct StagePlan {
  int techniqueCount = 0;
  int stageSamples = 0;              // N: the same for every pixel
  std::vector<int32_t> counts;       // [pixel·M + k], Σ_k = N
  std::vector<uint32_t> firstIndex;  // [pixel·M + k]
};

// Per pixel: this stage's unbiased RGB estimate and, per technique, Σ w and Σ w² of
// the luminance sample values w = Y(f)/p_α (kernels/pixel.h).
struct StageResult {
  std::vector<double> rgb;      // [pixel·3 + c]
  std::vector<double> moments;  // [(pixel·M + k)·2 + {0, 1}]
  double kernelSeconds = 0;
};

}  // namespace misalloc
