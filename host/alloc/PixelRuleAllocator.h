#pragma once
// The allocations that give each pixel its α by a formula of its own running sums or
// samples, the sums pooled over its neighbourhood (Pooling.h).

#include <vector>

#include "alloc/LinearAllocation.h"
#include "alloc/StageAllocator.h"

namespace misalloc {

enum class PixelRule {
  Heuristic,   // [HS14] eq. 4.20 (HeuristicAllocation.h)
  SigmaSqrtC,  // [SHS16] eq. 31 (SigmaAllocation.h)
  Linear,      // [SS23] eq. 14 (LinearAllocation.h), on the stored samples
};

// One pixel's α by `rule`. `samples`: the pixel's stored samples, which the linear rule
// needs; null for the others.
Allocation allocatePixel(PixelRule rule, const PixelStats& stats, const PixelSamples* samples,
                         const std::vector<double>& costs, ZeroWeightRule linearRule);

class PixelRuleAllocator final : public StageAllocator {
 public:
  // `poolRadius`: the sums pooled over (2r + 1)² pixels.
  PixelRuleAllocator(PixelRule rule, int poolRadius, ZeroWeightRule linearRule);

  // Every pixel's α from its pooled running sums (and for the linear rule its samples);
  // varianceRatio 1 and skipped 0 everywhere: the rules predict no gain.
  StageAllocation allocate(StageStatistics& stages, const std::vector<double>& costs) override;

 private:
  PixelRule rule_;
  int poolRadius_;
  ZeroWeightRule linearRule_;
};

}  // namespace misalloc
