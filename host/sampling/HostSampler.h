#pragma once
#include <vector>

#include "sampling/StageSampler.h"

namespace misalloc {

// The C++ reference of Sampler: the same kernels/pixel.h functions, one pixel per
// OpenMP iteration.
inline constexpr const char* kHostSamplerName = "host (C++ reference, OpenMP)";
class HostSampler : public StageSampler {
 public:
  HostSampler(const Scene& scene, const SamplerConfig& config = {});
  StageResult runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) override;

  std::vector<double> statistics() override { return stats_; }
  std::vector<float> storedSamples() override { return samples_; }
  void loadStatistics(const std::vector<double>& stats) override { stats_ = stats; }
  void loadStoredSamples(const std::vector<float>& samples) override { samples_ = samples; }
  const Device* storedSampleDevice() const override { return nullptr; }
  StoredSampleBuffer storedSampleBuffer() override { return {nullptr, nullptr, &samples_}; }

  std::vector<DeviceShare> deviceShares() const override { return {share_}; }
  std::string launchIdentity() const override;

 private:
  void forgetStages() override;

  std::vector<double> stats_;
  std::vector<float> samples_;
  DeviceShare share_;  // since reset()
};

}  // namespace misalloc
