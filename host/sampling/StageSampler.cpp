#include "sampling/StageSampler.h"

#include <stdexcept>

namespace misalloc {

StageResult StageSampler::run(const StagePlan& plan, uint64_t seed) {
  const int pixels = scene_.pixelCount();
  if (plan.techniqueCount != scene_.techniqueCount() || plan.counts.size() != size_t(pixels) * plan.techniqueCount ||
      plan.firstIndex.size() != plan.counts.size())
    throw std::logic_error("stage plan does not match the scene");
  return runPixels(plan, seed, takeSlots(plan), PixelRange{0, pixels});
}

LaunchWork StageSampler::launchWork(const StagePlan& plan) const {
  // A sampler that keeps no statistics runs its one kernel whatever the plan says.
  const bool statistics = plan.keepStatistics && keepsStatistics(config_);
  LaunchWork work = misalloc::launchWork(plan, config_.estimator, launchGroupSize(), pixelLanes(statistics));
  work.keepsStatistics = statistics;
  return work;
}

const CostModel& StageSampler::costModel() {
  if (!costModel_) costModel_ = calibrateCostModel(*this);
  return *costModel_;
}

void StageSampler::reset() {
  forgetSlots();
  forgetStages();
}

}  // namespace misalloc
