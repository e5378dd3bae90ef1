#include "alloc/GridSearchAllocator.h"

#include <fmt/format.h>

#include <memory>
#include <stdexcept>

namespace misalloc {
namespace {

// The search a sampler keeps (StageStatistics::kept): on the device that holds its stored
// samples, else the C++ reference on the host.
struct KeptGridSearch final : StageStatistics::Kept {
  std::unique_ptr<GridSearch> device;
  std::unique_ptr<GridSearchReference> host;

  GridSearchResult run(const StoredSamples& stored, const std::vector<double>& costs, GridRule rule,
                       const std::optional<PooledSelection>& pooling) {
    if (device) return device->run(*stored.where.buffer, stored.layout, costs, rule, pooling);
    return host->run(*stored.where.host, stored.layout, costs, rule, pooling);
  }
  void reset() { device ? device->reset() : host->reset(); }
};

// Rule (b) ranks the optimal weights' variance where the config asks for them, but not
// with the optimal envmap pdf's bank: there the stage's own envmap pdf depends on α
// (kernels/envmap.h, bankEntryOf), while the samples hold the pdf of the table they were
// drawn from, and a stage whose table differs keeps the balance heuristic
// (OptimalWeights.h, kWeightsOtherEnvmapTable), which its α must then suit.
bool ranksOptimalWeights(const StageStatistics& stages) {
  return stages.config().optimalWeights && !stages.scene().tables.followsEnvmapShare();
}

KeptGridSearch& keptSearch(StageStatistics& stages) {
  if (auto* kept = dynamic_cast<KeptGridSearch*>(stages.kept().get())) return *kept;
  const Scene& scene = stages.scene();
  const SamplerConfig& config = stages.config();
  auto kept = std::make_unique<KeptGridSearch>();
  if (const Device* device = stages.storedSampleDevice()) {
    try {
      kept->device =
          std::make_unique<GridSearch>(*device, sampleColumns(scene, config), scene.pixelCount(), config.gridSize,
                                       config.runningSums, ranksOptimalWeights(stages), scene.surfaces);
      kept->device->reserve(config.sampleCapacity);
    } catch (const cl::Error& e) {
      // The grid's sums and scores are the search's largest buffers.
      throw explainBufferError(e, *device, fmt::format("--grid-u {}", config.gridSize), scene.pixelCount());
    }
  } else {
    kept->host =
        std::make_unique<GridSearchReference>(sampleColumns(scene, config), scene.pixelCount(), config.gridSize,
                                              config.runningSums, ranksOptimalWeights(stages), scene.surfaces);
  }
  stages.kept() = std::move(kept);
  return static_cast<KeptGridSearch&>(*stages.kept());
}

}  // namespace

GridSearchAllocator::GridSearchAllocator(StageStatistics& stages, GridRule rule, std::optional<PooledSelection> pooling)
    : rule_(rule), pooling_(pooling) {
  const SamplerConfig& config = stages.config();
  if (config.gridSize <= 0 || config.sampleCapacity <= 0)
    throw std::logic_error("grid search on a sampler that does not keep what it needs");
  keptSearch(stages).reset();
  bytesPerPixel_ = gridSearchBytesPerPixel(sampleColumns(stages.scene(), config), config.gridSize, config.runningSums,
                                           ranksOptimalWeights(stages));
}

StageAllocation GridSearchAllocator::allocate(StageStatistics& stages, const std::vector<double>& costs) {
  GridSearchResult search = keptSearch(stages).run(stages.takeStoredSamples(), costs, rule_, pooling_);
  return {std::move(search.allocations), std::move(search.varianceRatio), std::move(search.skipped),
          std::move(search.heldOutVariance)};
}

}  // namespace misalloc
