#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "sampling/GridSearch.h"
#include "sampling/Stage.h"
#include "scene/Scene.h"

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
  int searched_ = 0;     // samples per pixel that the grid searches have added
  int taken_ = 0;        // samples per pixel taken so far
  bool closed_ = false;  // a stage without statistics was taken: it must be the last
};

// Whether a sampler with this config keeps anything beyond the stage estimates, and
// the config of its stages that keep nothing (StagePlan::keepStatistics false).
bool keepsStatistics(const SamplerConfig& config);
SamplerConfig plainConfig(SamplerConfig config);

// Padding lanes of the stored samples: technique 0, f = 0 and every pdf 1, so that
// the grid search may read them as samples that contribute nothing.
std::vector<float> emptyStoredSamples(const Scene& scene, int capacity);

}  // namespace misalloc
