#pragma once
#include <memory>
#include <vector>

#include "sampling/StageSampler.h"

namespace misalloc {

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
  DeviceShare share_;                                // since reset()
};

}  // namespace misalloc
