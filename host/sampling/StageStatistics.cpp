#include "sampling/StageStatistics.h"

#include <algorithm>
#include <stdexcept>

#include "KernelCode.h"

namespace misalloc {

StageStatistics::StageStatistics(const Scene& scene, const SamplerConfig& config) : scene_(scene), config_(config) {
  if (config.sampleCapacity < 0) throw std::invalid_argument("negative sample capacity");
  if ((config.estimator == Estimator::OneSample || config.estimator == Estimator::Resampled) &&
      (config.statsMask != 0 || config.sampleCapacity > 0 || config.gridSize > 0))
    throw std::invalid_argument("the allocations' statistics are kept for the multi-sample estimators only");
  if ((config.estimator == Estimator::Resampled) != (config.risCandidates > 0))
    throw std::invalid_argument("resampling needs candidates, and only resampling takes them");
  if (config.optimalWeights && config.estimator != Estimator::MultiSample)
    throw std::invalid_argument("the optimal weights are those of the multi-sample estimator");
}

int StageStatistics::statSlots() const {
  return scene_.techniqueCount() * MA_STATS_PER_TECHNIQUE(int(config_.statsMask), scene_.techniqueCount());
}

size_t StageStatistics::storedSampleCount() const {
  return StoredSampleLayout{scene_.pixelCount(), sampleColumns(scene_, config_).count(), config_.sampleCapacity, 0}
      .floatCount();
}

int StageStatistics::takeSlots(const StagePlan& plan) {
  if (closed_) throw std::logic_error("a stage after the stage without statistics");
  if (!plan.keepStatistics) {
    closed_ = true;
    return 0;
  }
  const int slot = plan.samplesBefore - searched_;
  if (slot < 0) throw std::logic_error("stage overwrites samples the grid search already added");
  if (config_.sampleCapacity > 0 && slot + plan.stageSamples > config_.sampleCapacity)
    throw std::logic_error("stage overflows the stored-samples buffer");
  taken_ = plan.samplesBefore + plan.stageSamples;
  return slot;
}

void StageStatistics::forgetSlots() {
  taken_ = searched_ = 0;
  closed_ = false;
}

StoredSamples StageStatistics::takeStoredSamples() {
  if (config_.sampleCapacity <= 0) throw std::logic_error("a search on a sampler that stores no samples");
  StoredSamples stored{
      StoredSampleLayout{scene_.pixelCount(), sampleColumns(scene_, config_).count(), config_.sampleCapacity,
                         taken_ - searched_},
      storedSampleBuffer()};
  searched_ = taken_;
  return stored;
}

SampleColumns sampleColumns(const Scene& scene, const SamplerConfig& config) {
  const int M = scene.techniqueCount(), shares = scene.tables.shareColumns();
  const bool fits =
      shares > 0 && shares <= MA_MAX_BANK_SHARES && MA_STORED_COLUMNS(M, shares) <= MA_GRID_MAX_TECHNIQUES;
  return SampleColumns(M, config.shareColumns && fits ? shares : 0);
}

std::vector<float> emptyStoredSamples(const Scene& scene, const SamplerConfig& config, int spareRecords) {
  const int columns = sampleColumns(scene, config).count(), rows = MA_SAMPLE_RECORD_FLOATS(columns);
  std::vector<float> samples(StoredSampleLayout{scene.pixelCount(), columns, config.sampleCapacity, 0}.floatCount() +
                             std::size_t(spareRecords) * rows * 16);
  int q = 0;  // the value each row of 16 lanes holds (kernels/stats.h, storedSampleIndex)
  for (std::size_t row = 0; row < samples.size() / 16; ++row) {
    std::fill_n(samples.begin() + row * 16, 16, q < 2 ? 0.0f : 1.0f);
    q = q + 1 < rows ? q + 1 : 0;
  }
  return samples;
}

bool keepsStatistics(const SamplerConfig& config) { return config.statsMask != 0 || config.sampleCapacity > 0; }

SamplerConfig plainConfig(SamplerConfig config) {
  config.statsMask = 0;
  config.sampleCapacity = 0;
  config.gridSize = 0;
  config.shareColumns = false;
  return config;
}

}  // namespace misalloc
