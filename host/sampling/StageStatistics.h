#pragma once
#include <CL/opencl.hpp>
#include <cstddef>
#include <memory>
#include <vector>

#include "cl/Device.h"
#include "sampling/Stage.h"
#include "scene/Scene.h"

namespace misalloc {

// Where a sampler keeps its stored samples: in `buffer` on `device`, or in `host`
// memory.
struct StoredSampleBuffer {
  const Device* device = nullptr;
  const cl::Buffer* buffer = nullptr;
  const std::vector<float>* host = nullptr;
};

// The samples stored since the previous search, and where they are.
struct StoredSamples {
  StoredSampleLayout layout;
  StoredSampleBuffer where;
};

// What a sampler's stages leave for the allocation between them (alloc/StageAllocator.h),
// as its config asks: every pixel's running sums (kernels/stats.h) and the samples
// stored since the last search, kept across stages.
class StageStatistics {
 public:
  // Throws std::invalid_argument for a config that keeps statistics with the one-sample
  // estimator, which no allocation reads.
  StageStatistics(const Scene& scene, const SamplerConfig& config);
  virtual ~StageStatistics() = default;

  const Scene& scene() const { return scene_; }
  const SamplerConfig& config() const { return config_; }
  int statSlots() const;                       // running sums per pixel
  size_t storedSampleCount() const;            // floats in the stored-samples buffer
  int samplesTaken() const { return taken_; }  // per pixel, by the stages that keep statistics

  // The running sums, [pixel · slots + slot] (kernels/stats.h), and the stored
  // samples in the layout of kernels/stats.h's storedSampleIndex.
  virtual std::vector<double> statistics() = 0;
  virtual std::vector<float> storedSamples() = 0;
  // Overwrite the running sums / stored samples with those of statistics() /
  // storedSamples() of a sampler of the same scene and config.
  virtual void loadStatistics(const std::vector<double>& stats) = 0;
  virtual void loadStoredSamples(const std::vector<float>& samples) = 0;

  // The samples stored since the previous call, for a search that reads them where
  // they are and adds them to sums of its own (alloc/GridSearchAllocator.h): the next
  // stage stores from slot 0 again. Throws std::logic_error where the config stores none.
  StoredSamples takeStoredSamples();
  // The device that holds the stored samples, on which a search reads them; null for
  // host memory.
  virtual const Device* storedSampleDevice() const = 0;
  // Where the stored samples are, brought up to date for a search.
  virtual StoredSampleBuffer storedSampleBuffer() = 0;

  // What an allocation builds once for these stored samples and keeps from render to
  // render: the grid search's kernels and sums (alloc/GridSearchAllocator.h). Held here
  // because it reads the sampler's buffers and so must not outlive them.
  struct Kept {
    virtual ~Kept() = default;
  };
  std::unique_ptr<Kept>& kept() { return kept_; }

 protected:
  // Records the stage and returns the stored-samples slot of its first sample. Slot i
  // holds sample searched_ + i: the samples before are in a search's sums.
  // Throws std::logic_error if the stage does not fit.
  int takeSlots(const StagePlan& plan);
  // Every slot free again, for a new render.
  void forgetSlots();

  const Scene& scene_;
  SamplerConfig config_;

 private:
  int searched_ = 0;     // samples per pixel that a search has taken (takeStoredSamples)
  int taken_ = 0;        // samples per pixel taken so far
  bool closed_ = false;  // a stage without statistics was taken: it must be the last
  std::unique_ptr<Kept> kept_;
};

// Whether a sampler with this config keeps anything beyond the stage estimates, and
// the config of its stages that keep nothing (StagePlan::keepStatistics false).
bool keepsStatistics(const SamplerConfig& config);
SamplerConfig plainConfig(SamplerConfig config);

// The columns of the samples that a sampler with this config stores for `scene`: share
// columns where the config asks for them and the scene's envmap pdf has a bank whose
// shares fit the grid search's columns.
SampleColumns sampleColumns(const Scene& scene, const SamplerConfig& config);

// Padding lanes of the stored samples: column 0, f = 0 and every pdf 1, so that the
// grid search may read them as samples that contribute nothing; then `spareRecords`
// records of 16 lanes more, alike. Written once, at their full size.
std::vector<float> emptyStoredSamples(const Scene& scene, const SamplerConfig& config, int spareRecords = 0);

}  // namespace misalloc
