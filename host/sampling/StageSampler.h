#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "sampling/CostModel.h"
#include "sampling/DeviceReport.h"
#include "sampling/LaunchWork.h"
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

  // What a launch of `plan` executes, as this sampler runs it (LaunchWork.h).
  LaunchWork launchWork(const StagePlan& plan) const;
  // The model of this sampler's launch times: the one set, else calibrated at the first
  // call (calibrateCostModel) and kept for every later render, which it predicts.
  const CostModel& costModel();
  void setCostModel(CostModel model) { costModel_ = std::move(model); }
  // What its launch times depend on besides the scene: the devices and the kernels as
  // built (their source and options). The cost cache's key (render/CostCache.h).
  virtual std::string launchIdentity() const = 0;

  // The pixels that run a technique's loop together: a work-group (Sampler).
  virtual int launchGroupSize() const { return 1; }
  // > 0: the stages that keep statistics (`keepsStatistics`: running sums or stored
  // samples) or those that keep none sample one pixel at a time across a work-group of
  // this many lanes (Sampler on a CPU, kernels/sample.cl samplePixelStage).
  virtual int pixelLanes(bool /*keepsStatistics*/) const { return 0; }

 protected:
  // Clears the running sums and device shares.
  virtual void forgetStages() = 0;

 private:
  std::optional<CostModel> costModel_;
};

}  // namespace misalloc
