#pragma once
#include <cstdint>

#include "sampling/DeviceReport.h"
#include "sampling/Stage.h"
#include "sampling/StageStatistics.h"

namespace misalloc {

// Takes sampling stages for every pixel, keeping what they leave for the allocation
// (StageStatistics) and recording where they ran (DeviceReport).
class StageSampler : public StageStatistics, public DeviceReport {
 public:
  StageSampler(const Scene& scene, const SamplerConfig& config) : StageStatistics(scene, config) {}

  // One stage for every pixel.
  StageResult run(const StagePlan& plan, uint64_t seed);
  // Forgets every stage taken so far (running sums, stored samples, device shares), so
  // that the next stage starts a new render on the same compiled kernels.
  void reset();

  // One stage for the pixels of `range` only: their estimates and moments, their running
  // sums, their stored samples from slot `firstSlot` on. For a sampler that hands a
  // stage out in tiles (TiledSampler), which takes the slots itself; run() for any other
  // caller.
  virtual StageResult runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) = 0;

 protected:
  // Clears the running sums and device shares.
  virtual void forgetStages() = 0;
};

}  // namespace misalloc
