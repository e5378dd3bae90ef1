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

void StageSampler::reset() {
  forgetSlots();
  forgetStages();
}

}  // namespace misalloc
