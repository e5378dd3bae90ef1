#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "Constants.h"
#include "KernelCode.h"

namespace misalloc {

enum class Estimator {
  MultiSample,       // balance heuristic with deterministic counts ([HS14] eq. 4.1)
  OneSample,         // balance heuristic, technique drawn with probabilities α
  CountIndependent,  // weights p_k/Σ_l p_l whatever the counts ([SHS16] eq. 26)
  Resampled,         // technique 0 alone, each sample resampled from envmap candidates ([TCE05], kernels/ris.h)
};

// What one sampling stage takes per pixel: counts n_k (multi-sample; for the
// one-sample estimator they give the selection probabilities α_k = n_k/N) and the
// index of each technique's first sample, which keys its random numbers so that
// later stages never reuse an earlier stage's.
struct StagePlan {
  int techniqueCount = 0;
  int stageSamples = 0;              // N: the same for every pixel
  int samplesBefore = 0;             // samples each pixel took in earlier stages
  std::vector<int32_t> counts;       // [pixel·M + k], Σ_k = N, or 0 where a pixel takes none (the background)
  std::vector<uint32_t> firstIndex;  // [pixel·M + k]
  // False for a stage that no allocation follows: it runs the kernel without running
  // sums or stored samples, as fast as a fixed split's. Only the last stage may.
  bool keepStatistics = true;
  // With optimal weights (SamplerConfig::optimalWeights), each pixel's coefficients a_{c,k}
  // at [pixel·3M + c·M + k] (kernels/pixel.h, OptimalCoefficients); empty: all 0, the
  // balance heuristic.
  std::vector<float> optimalCoefficients;
};

// A stage's counts [pixel·M + k] where every pixel takes the same `counts` ([k]).
inline std::vector<int32_t> sameCountsEverywhere(int pixels, const std::vector<int>& counts) {
  std::vector<int32_t> out;
  out.reserve(std::size_t(pixels) * counts.size());
  for (int p = 0; p < pixels; ++p) out.insert(out.end(), counts.begin(), counts.end());
  return out;
}

// The pixels [begin, end) of the image, in index order: a tile of a stage.
struct PixelRange {
  int begin = 0, end = 0;
  int size() const { return end - begin; }
};

// Per pixel: this stage's unbiased RGB estimate and, per technique, Σ w and Σ w² of
// the luminance sample values w (kernels/pixel.h).
// A tile's result holds its pixels only, pixel counted from the tile's first.
struct StageResult {
  std::vector<double> rgb;      // [pixel·3 + c]
  std::vector<double> moments;  // [(pixel·M + k)·2 + {0, 1}]
  double kernelSeconds = 0;
};

// What a sampler keeps beyond the stage estimates, for the allocations.
struct SamplerConfig {
  Estimator estimator = Estimator::MultiSample;
  unsigned statsMask = 0;  // running sums kept across stages (kernels/stats.h)
  // > 0: every sample taken since the last grid search (all of them, without searches)
  // is stored, up to this many per pixel.
  int sampleCapacity = 0;
  int gridSize = 0;  // > 0: grid searches ([HS14] Algorithm 1) over about this many combinations
  // The grid searches keep running sums, for renders that search more than once.
  bool runningSums = true;
  // The stored samples carry the envmap's pdf under every share of the optimal pdf's
  // bank, where the scene has one (SampleColumns): for the grid search's rule (b).
  bool shareColumns = false;
  int risCandidates = 0;  // the resampled estimator's candidates per sample; 0 for the others
  // [Kon19]'s optimal weights with the stage plans' coefficients (multi-sample only).
  bool optimalWeights = false;
};

// The columns of a stored sample (kernels/stats.h): the pdfs an allocation weighs, one
// per technique, or with share columns S > 0 the envmap's under each of the bank's S
// shares, then the other techniques.
struct SampleColumns {
  int techniqueCount = 0;
  int shareColumns = 0;

  SampleColumns(int techniqueCount, int shareColumns = 0) : techniqueCount(techniqueCount), shareColumns(shareColumns) {}
  int count() const { return MA_STORED_COLUMNS(techniqueCount, shareColumns); }
  int techniqueOf(int column) const { return kern::techniqueOfColumn(column, shareColumns); }
};

// Where the stored samples are: the blocked float layout of kernels/stats.h
// (storedSampleIndex), `capacity` slots per pixel of which the first `taken` are filled
// for every pixel, pixels padded to a multiple of 16. A search reads the `taken`
// samples as those taken since the previous search.
struct StoredSampleLayout {
  int pixelCount = 0;
  int columns = 0;  // SampleColumns::count
  int capacity = 0;
  int taken = 0;

  std::size_t floatCount() const {
    return paddedPixelCount(std::size_t(pixelCount)) * std::size_t(capacity) *
           std::size_t(MA_SAMPLE_RECORD_FLOATS(columns));
  }
};

}  // namespace misalloc
