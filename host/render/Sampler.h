#pragma once
#include <CL/opencl.hpp>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "alloc/GridSearch.h"
#include "cl/Device.h"
#include "render/Scene.h"
#include "render/Stage.h"

namespace misalloc {

// Takes sampling stages for every pixel and keeps the running sums and stored samples
// that its config asks for, across stages.
class StageSampler {
 public:
  StageSampler(const Scene& scene, const SamplerConfig& config);
  virtual ~StageSampler() = default;

  virtual StageResult run(const StagePlan& plan, uint64_t seed) = 0;
  // The running sums, [pixel · slots + slot] (kernels/stats.h), and the stored
  // samples in the layout of kernels/stats.h's storedSampleIndex.
  virtual std::vector<double> statistics() = 0;
  virtual std::vector<float> storedSamples() = 0;
  // 000 Algorithm 1 over the first `taken` stored samples of every pixel
  // (kernels/gridsearch.cl on a device, its C++ reference on the host).
  virtual GridSearchResult searchWeights(const std::vector<double>& costs, int gridSize, GridRule rule,
                                         int taken) = 0;

  const Scene& scene() const { return scene_; }
  const SamplerConfig& config() const { return config_; }
  int statSlots() const;             // running sums per pixel
  size_t storedSampleCount() const;  // floats in the stored-samples buffer
  StoredSampleLayout storedSampleLayout(int taken) const;

 protected:
  const Scene& scene_;
  SamplerConfig config_;
};

// The `-D` options that compile kernels/sample.cl for exactly this scene, estimator,
// statistics and work-group size.
std::string sampleKernelOptions(const Scene& scene, const SamplerConfig& config, int localSize);

// Runs kernels/sample.cl (sampleStage) on a device. The program is built and the
// scene uploaded once; each run() takes one stage for every pixel.
class Sampler : public StageSampler {
 public:
  Sampler(const Device& device, const Scene& scene, const SamplerConfig& config = {}, int localSize = 8);
  StageResult run(const StagePlan& plan, uint64_t seed) override;
  std::vector<double> statistics() override;
  std::vector<float> storedSamples() override;
  GridSearchResult searchWeights(const std::vector<double>& costs, int gridSize, GridRule rule, int taken) override;

 private:
  const Device& device_;
  std::unique_ptr<GridSearch> gridSearch_;  // built at the first search
  int localSize_;
  bool doubleSums_;
  cl::Kernel kernel_;
  cl::Buffer texels_, cdfTable_, aliasTable_, brdfParams_, stats_, samples_;
};

// The C++ reference of Sampler: the same kernels/pixel.h functions, one pixel per
// OpenMP iteration.
class HostSampler : public StageSampler {
 public:
  HostSampler(const Scene& scene, const SamplerConfig& config = {});
  StageResult run(const StagePlan& plan, uint64_t seed) override;
  std::vector<double> statistics() override { return stats_; }
  std::vector<float> storedSamples() override { return samples_; }
  GridSearchResult searchWeights(const std::vector<double>& costs, int gridSize, GridRule rule, int taken) override {
    return gridSearchReference(samples_, storedSampleLayout(taken), costs, gridSize, rule);
  }

 private:
  std::vector<double> stats_;
  std::vector<float> samples_;
};

// Padding lanes of the stored samples: technique 0, f = 0 and every pdf 1, so that
// the grid search may read them as samples that contribute nothing.
std::vector<float> emptyStoredSamples(const Scene& scene, int capacity);

}  // namespace misalloc
