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

  // One stage for every pixel.
  StageResult run(const StagePlan& plan, uint64_t seed);
  // The running sums, [pixel · slots + slot] (kernels/stats.h), and the stored
  // samples in the layout of kernels/stats.h's storedSampleIndex.
  virtual std::vector<double> statistics() = 0;
  virtual std::vector<float> storedSamples() = 0;
  // [HS14] Algorithm 1 over every sample taken so far, with the grid of config().gridSize:
  // the searches keep running sums, and each adds the samples of the stages since the
  // one before (kernels/gridsearch.cl on a device, its C++ reference on the host).
  // `pooling`: select by rule (b) over neighbourhoods, with the skip rule.
  GridSearchResult searchWeights(const std::vector<double>& costs, GridRule rule,
                                 const std::optional<PooledSelection>& pooling = std::nullopt);
  // Forgets every stage taken so far (running sums, the grid searches' sums), so that
  // the next stage starts a new render on the same compiled kernels.
  void reset();

  const Scene& scene() const { return scene_; }
  const SamplerConfig& config() const { return config_; }
  int statSlots() const;               // running sums per pixel
  size_t storedSampleCount() const;    // floats in the stored-samples buffer
  size_t searchBytesPerPixel() const;  // the grid searches' running sums

  // Where the stages since reset() ran, for the report: every device's share (one
  // entry for a single device), and how far apart their last tiles finished.
  virtual std::vector<DeviceShare> deviceShares() const = 0;
  virtual double imbalanceSeconds() const { return 0; }

 protected:
  // TiledSampler drives its members' tiles and keeps their sums in step.
  friend class TiledSampler;

  // One stage for the pixels of `range` only: their estimates and moments, their running
  // sums, their stored samples from slot `firstSlot` on.
  virtual StageResult runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) = 0;
  // Overwrite the running sums / stored samples with those of statistics() / storedSamples().
  virtual void loadStatistics(const std::vector<double>& stats) = 0;
  virtual void loadStoredSamples(const std::vector<float>& samples) = 0;

  // Records the stage and returns the stored-samples slot of its first sample. Slot i
  // holds sample searched_ + i: the samples before are in the grid searches' sums.
  // Throws std::logic_error if the stage does not fit.
  int takeSlots(const StagePlan& plan);
  virtual GridSearchResult search(const StoredSampleLayout& layout, const std::vector<double>& costs, GridRule rule,
                                  const std::optional<PooledSelection>& pooling) = 0;
  virtual void forgetStages() = 0;

  const Scene& scene_;
  SamplerConfig config_;

 private:
  int searched_ = 0;  // samples per pixel that the grid searches have added
  int taken_ = 0;     // samples per pixel taken so far
  bool closed_ = false;  // a stage without statistics was taken: it must be the last
};

// Whether a sampler with this config keeps anything beyond the stage estimates, and
// the config of its stages that keep nothing (StagePlan::keepStatistics false).
bool keepsStatistics(const SamplerConfig& config);
SamplerConfig plainConfig(SamplerConfig config);

// The `-D` options that compile kernels/sample.cl for exactly this scene, estimator,
// statistics and work-group size.
std::string sampleKernelOptions(const Scene& scene, const SamplerConfig& config, int localSize);

// A scene's read-only device buffers: the envmap's tables and the BRDF grid. Devices
// that share a context (the sub-devices of one device, cl/Device.h) share one copy, so
// that their caches hold one set of tables.
class SceneBuffers {
 public:
  SceneBuffers(const Device& device, const Scene& scene);
  cl_context context() const { return context_; }

  cl::Buffer texels, cdfTable, aliasTable, brdfParams;

 private:
  cl_context context_;
};

// Runs kernels/sample.cl (sampleStage) on a device. The program is built and the
// scene uploaded once; each run() takes one stage for every pixel.
class Sampler : public StageSampler {
 public:
  // localSize 0: the device's own (cl/LaunchShape.h); > 0: --local-size, checked against it.
  // `sceneBuffers`: made for this device's context, shared with other samplers; null:
  // its own.
  Sampler(const Device& device, const Scene& scene, const SamplerConfig& config = {}, int localSize = 0,
          std::shared_ptr<const SceneBuffers> sceneBuffers = nullptr);
  int localSize() const { return localSize_; }
  std::vector<double> statistics() override;
  std::vector<float> storedSamples() override;
  std::vector<DeviceShare> deviceShares() const override;

 protected:  // tests/test_devices.cpp injects failures into runPixels
  StageResult runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) override;
  void loadStatistics(const std::vector<double>& stats) override;
  void loadStoredSamples(const std::vector<float>& samples) override;
  GridSearchResult search(const StoredSampleLayout& layout, const std::vector<double>& costs, GridRule rule,
                          const std::optional<PooledSelection>& pooling) override;
  void forgetStages() override;

 private:
  const Device& device_;
  std::unique_ptr<GridSearch> gridSearch_;  // where config().gridSize > 0
  int localSize_;
  bool doubleSums_;
  cl::Kernel kernel_, plainKernel_;  // with the config's statistics, and without (plainConfig)
  std::shared_ptr<const SceneBuffers> sceneBuffers_;
  cl::Buffer stats_, samples_;
  // A stage's per-pixel inputs and outputs, whole-image sized so that a tile writes its rows.
  cl::Buffer counts_, firstIndex_, pixelOrder_, rgb_, moments_;
  DeviceShare share_;  // since reset()
};

// The C++ reference of Sampler: the same kernels/pixel.h functions, one pixel per
// OpenMP iteration.
inline constexpr const char* kHostSamplerName = "host (C++ reference, OpenMP)";
class HostSampler : public StageSampler {
 public:
  HostSampler(const Scene& scene, const SamplerConfig& config = {});
  std::vector<double> statistics() override { return stats_; }
  std::vector<float> storedSamples() override { return samples_; }
  std::vector<DeviceShare> deviceShares() const override { return {share_}; }

 private:
  StageResult runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) override;
  void loadStatistics(const std::vector<double>& stats) override { stats_ = stats; }
  void loadStoredSamples(const std::vector<float>& samples) override { samples_ = samples; }
  GridSearchResult search(const StoredSampleLayout& layout, const std::vector<double>& costs, GridRule rule,
                          const std::optional<PooledSelection>& pooling) override {
    return gridSearch_->run(samples_, layout, costs, rule, pooling);
  }
  void forgetStages() override;

  std::vector<double> stats_;
  std::vector<float> samples_;
  std::unique_ptr<GridSearchReference> gridSearch_;  // where config().gridSize > 0
  DeviceShare share_;  // since reset()
};

// Padding lanes of the stored samples: technique 0, f = 0 and every pdf 1, so that
// the grid search may read them as samples that contribute nothing.
std::vector<float> emptyStoredSamples(const Scene& scene, int capacity);

}  // namespace misalloc
