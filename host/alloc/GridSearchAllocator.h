#pragma once
// The grid search as a stage allocation: [HS14] Algorithm 1 over every sample a render
// took, on the device that holds the sampler's stored samples (GridSearch) or on the host
// (GridSearchReference).

#include <optional>
#include <vector>

#include "alloc/GridSearch.h"
#include "alloc/StageAllocator.h"

namespace misalloc {

class GridSearchAllocator final : public StageAllocator {
 public:
  // Starts a new search over the samples a sampler stores (`stages`), whose config
  // gives the grid (gridSize) and whether the sums are kept (runningSums). The search's
  // kernels and buffers are built at the sampler's first search and kept with it
  // (StageStatistics::kept), so that later renders do not pay for them. `pooling`:
  // rule (b) over neighbourhoods, with the skip rule. Throws std::logic_error for a
  // sampler that keeps no grid, DeviceError where the grid's buffers do not fit the
  // device.
  GridSearchAllocator(StageStatistics& stages, GridRule rule, std::optional<PooledSelection> pooling);

  // Adds the samples stored since the last search to the search's sums and selects
  // by all of them.
  StageAllocation allocate(StageStatistics& stages, const std::vector<double>& costs) override;
  std::size_t bytesPerPixel() const override { return bytesPerPixel_; }

 private:
  GridRule rule_;
  std::optional<PooledSelection> pooling_;
  std::size_t bytesPerPixel_;
};

}  // namespace misalloc
