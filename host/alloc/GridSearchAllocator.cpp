#include "alloc/GridSearchAllocator.h"

#include <fmt/format.h>

#include <memory>
#include <stdexcept>

namespace misalloc {
namespace {

// The search a sampler keeps (StageSampler::kept): on the device that holds its stored
// samples, else the C++ reference on the host.
struct KeptGridSearch final : StageSampler::Kept {
  std::unique_ptr<GridSearch> device;
  std::unique_ptr<GridSearchReference> host;

  GridSearchResult run(const StoredSamples& stored, const std::vector<double>& costs, GridRule rule,
                       const std::optional<PooledSelection>& pooling) {
    if (device) return device->run(*stored.where.buffer, stored.layout, costs, rule, pooling);
    return host->run(*stored.where.host, stored.layout, costs, rule, pooling);
  }
  void reset() { device ? device->reset() : host->reset(); }
};

KeptGridSearch& keptSearch(StageSampler& sampler) {
  if (auto* kept = dynamic_cast<KeptGridSearch*>(sampler.kept().get())) return *kept;
  const Scene& scene = sampler.scene();
  const SamplerConfig& config = sampler.config();
  auto kept = std::make_unique<KeptGridSearch>();
  if (const Device* device = sampler.storedSampleDevice()) {
    try {
      kept->device = std::make_unique<GridSearch>(*device, scene.techniqueCount(), scene.pixelCount(), config.gridSize,
                                                  config.runningSums);
    } catch (const cl::Error& e) {
      // The grid's sums and scores are the search's largest buffers.
      throw explainBufferError(e, *device, fmt::format("--grid-u {}", config.gridSize), scene.pixelCount());
    }
  } else {
    kept->host = std::make_unique<GridSearchReference>(scene.techniqueCount(), scene.pixelCount(), config.gridSize,
                                                       config.runningSums);
  }
  sampler.kept() = std::move(kept);
  return static_cast<KeptGridSearch&>(*sampler.kept());
}

}  // namespace

GridSearchAllocator::GridSearchAllocator(StageSampler& sampler, std::vector<double> costs, GridRule rule,
                                         std::optional<PooledSelection> pooling)
    : costs_(std::move(costs)), rule_(rule), pooling_(pooling) {
  const SamplerConfig& config = sampler.config();
  if (config.gridSize <= 0 || config.sampleCapacity <= 0)
    throw std::logic_error("grid search on a sampler that does not keep what it needs");
  keptSearch(sampler).reset();
  bytesPerPixel_ = gridSearchBytesPerPixel(sampler.scene().techniqueCount(), config.gridSize, config.runningSums);
}

StageAllocation GridSearchAllocator::allocate(StageSampler& sampler) {
  GridSearchResult search = keptSearch(sampler).run(sampler.takeStoredSamples(), costs_, rule_, pooling_);
  return {std::move(search.allocations), std::move(search.varianceRatio), std::move(search.skipped)};
}

}  // namespace misalloc
