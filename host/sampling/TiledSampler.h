#pragma once
#include <memory>
#include <string>
#include <vector>

#include "sampling/Sampler.h"

namespace misalloc {

// One render split across several devices. Every stage is handed out in tiles of
// pixels from one TileQueue, sized by each device's measured rate. A pixel's random
// numbers are keyed on the pixel (kernels/rng.h) and its sums run in the same order
// wherever it runs, so the image is the one a single device of the same arithmetic
// makes, bit for bit. Each member keeps whole-image running sums and stored samples;
// after a stage that keeps statistics, the rows each member ran are gathered here, and
// loaded into every member before the next such stage, so that any device can run any
// pixel, and into the first member before a grid search, which runs there.
//
// A member that fails (an OpenCL error) is retired: its tile, and every tile it ran in
// a stage whose running sums it alone holds, run again on the others, and its report
// entry says why. With no member left, or when a grid search needs the first member and
// it is lost (it holds the sums of the earlier searches), DeviceError.
class TiledSampler : public StageSampler {
 public:
  // Members built for the same scene and config, one per device.
  TiledSampler(const Scene& scene, const SamplerConfig& config, std::vector<std::unique_ptr<StageSampler>> members);

  // A stage's result: the wall time from the first launch to the last finish is its
  // kernelSeconds, the time the cost-aware allocations pay for a sample.
  StageResult runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) override;

  std::vector<double> statistics() override { return stats_; }
  std::vector<float> storedSamples() override { return samples_; }
  void loadStatistics(const std::vector<double>& stats) override;
  void loadStoredSamples(const std::vector<float>& samples) override;
  // The first member's: a search reads the samples there, where its sums of earlier
  // searches are.
  const Device* storedSampleDevice() const override { return members_[0]->storedSampleDevice(); }
  StoredSampleBuffer storedSampleBuffer() override;

  std::vector<DeviceShare> deviceShares() const override;
  // The members', in their order: the tiles' shares follow their speeds.
  std::string launchIdentity() const override;
  double imbalanceSeconds() const override { return imbalanceSeconds_; }
  // Tiles run on every member at once: work-groups taken as large as the largest.
  int launchGroupSize() const override;
  int pixelLanes(bool keepsStatistics) const override;

 private:
  void forgetStages() override;

  bool live(size_t member) const { return failures_[member].empty(); }
  // Gathers the rows each member ran in the stage into stats_ and samples_.
  void gatherStatistics(const std::vector<std::vector<PixelRange>>& ran);
  // Loads stats_ and samples_ into the first `count` live members that lack them.
  void loadMembers(size_t count);

  std::vector<std::unique_ptr<StageSampler>> members_;
  std::vector<double> sampleRates_;    // samples per second of each member, 0 until measured
  std::vector<std::string> failures_;  // per member: why it was retired, empty while it runs
  std::vector<double> stats_;          // every pixel's running sums after the last stage
  std::vector<float> samples_;         // and its stored samples
  std::vector<unsigned char> loaded_;  // per member: it holds stats_ and samples_
  double imbalanceSeconds_ = 0;        // Σ over stages: last finish − first finish
};

}  // namespace misalloc
