#pragma once
// The allocation between a render's stages: every pixel's weights α for the next stage,
// from what the stages before it left. Per-pixel rules (PixelRuleAllocator.h) and the
// grid search (GridSearchAllocator.h) implement it; render/Render.cpp calls it between
// stages and apportions its α into counts (Apportion.h).

#include <cstddef>
#include <vector>

#include "alloc/Allocation.h"
#include "sampling/StageStatistics.h"

namespace misalloc {

struct StageAllocation {
  std::vector<Allocation> allocations;  // per pixel
  // Per pixel, V(equal)/V(α) of the multi-sample estimator as the pixel's neighbours
  // predict it (GridSearchResult::varianceRatio); 1 where nothing predicts it. It
  // weighs the pilot (StageWeights.h, pilotWeight).
  std::vector<float> varianceRatio;
  std::vector<unsigned char> skipped;  // per pixel: 1 where the skip rule kept equal weights
  // exact: per pixel, the variance of equal weights and of α by its held-out samples
  // (GridSearchResult::heldOutVariance); empty for the other allocations.
  std::vector<float> heldOutVariance;
};

class StageAllocator {
 public:
  virtual ~StageAllocator() = default;

  // Every pixel's α for the next stage, from what the stages of a sampler since its
  // reset() left in `stages`: its running sums, its stored samples. `costs`: c_k per
  // sample of the kernel that runs that stage (sampling/CostModel.h).
  virtual StageAllocation allocate(StageStatistics& stages, const std::vector<double>& costs) = 0;
  // What the allocation keeps per pixel beside the sampler's running sums and stored
  // samples, for the report.
  virtual std::size_t bytesPerPixel() const { return 0; }
};

}  // namespace misalloc
