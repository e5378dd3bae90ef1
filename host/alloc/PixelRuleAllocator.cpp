#include "alloc/PixelRuleAllocator.h"

#include <optional>
#include <stdexcept>

#include "alloc/HeuristicAllocation.h"
#include "alloc/Pooling.h"
#include "alloc/SigmaAllocation.h"
#include "stats/RunningStats.h"

namespace misalloc {

Allocation allocatePixel(PixelRule rule, const PixelStats& stats, const PixelSamples* samples,
                         const std::vector<double>& costs, ZeroWeightRule linearRule) {
  switch (rule) {
    case PixelRule::Heuristic:
      return allocateHeuristic(stats, costs);  // [HS14] eq. 4.20
    case PixelRule::SigmaSqrtC:
      return allocateSigmaSqrtC(stats, costs);  // [SHS16] eq. 31
    case PixelRule::Linear:
      if (!samples) throw std::logic_error("the linear rule without the pixel's samples");
      return allocateLinear(*samples, linearRule);  // [SS23] eq. 14
  }
  throw std::logic_error("unknown per-pixel rule");
}

PixelRuleAllocator::PixelRuleAllocator(PixelRule rule, int poolRadius, ZeroWeightRule linearRule)
    : rule_(rule), poolRadius_(poolRadius), linearRule_(linearRule) {}

StageAllocation PixelRuleAllocator::allocate(StageStatistics& stages, const std::vector<double>& costs) {
  const Scene& scene = stages.scene();
  const SamplerConfig& config = stages.config();
  const int pixels = scene.pixelCount(), M = scene.techniqueCount(), slots = stages.statSlots();
  std::vector<double> stats = stages.statistics();
  poolNeighbourhood(stats, scene.grid.width, scene.grid.height, slots, poolRadius_, scene.surfaces);
  const std::vector<float> stored = rule_ == PixelRule::Linear ? stages.storedSamples() : std::vector<float>{};
  const int taken = stages.samplesTaken();
  StageAllocation out{
      std::vector<Allocation>(pixels), std::vector<float>(pixels, 1.0f), std::vector<unsigned char>(pixels, 0), {}};
#pragma omp parallel for schedule(dynamic, 256)
  for (int p = 0; p < pixels; ++p) {
    PixelStats pixelStats = decodePixelStats(stats.data() + size_t(p) * slots, config.statsMask, M);
    std::optional<PixelSamples> samples;
    if (!stored.empty()) samples = decodePixelSamples(stored, p, taken, config.sampleCapacity, M);
    out.allocations[p] = allocatePixel(rule_, pixelStats, samples ? &*samples : nullptr, costs, linearRule_);
  }
  return out;
}

}  // namespace misalloc
