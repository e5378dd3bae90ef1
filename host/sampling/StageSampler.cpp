#include "sampling/StageSampler.h"

#include <algorithm>
#include <stdexcept>

#include "Constants.h"
#include "KernelCode.h"

namespace misalloc {

StageSampler::StageSampler(const Scene& scene, const SamplerConfig& config) : scene_(scene), config_(config) {
  if (config.sampleCapacity < 0) throw std::invalid_argument("negative sample capacity");
  if (config.estimator == Estimator::OneSample &&
      (config.statsMask != 0 || config.sampleCapacity > 0 || config.gridSize > 0))
    throw std::invalid_argument("the allocations' statistics are kept for the multi-sample estimators only");
}

int StageSampler::statSlots() const {
  return scene_.techniqueCount() * MA_STATS_PER_TECHNIQUE(int(config_.statsMask), scene_.techniqueCount());
}

size_t StageSampler::storedSampleCount() const {
  size_t paddedPixels = paddedPixelCount(size_t(scene_.pixelCount()));
  return paddedPixels * size_t(config_.sampleCapacity) * size_t(scene_.techniqueCount() + 2);
}

int StageSampler::takeSlots(const StagePlan& plan) {
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

StoredSamples StageSampler::takeStoredSamples() {
  if (config_.sampleCapacity <= 0) throw std::logic_error("a search on a sampler that stores no samples");
  StoredSamples stored{
      StoredSampleLayout{scene_.pixelCount(), scene_.techniqueCount(), config_.sampleCapacity, taken_ - searched_},
      storedSampleBuffer()};
  searched_ = taken_;
  return stored;
}

StageResult StageSampler::run(const StagePlan& plan, uint64_t seed) {
  const int pixels = scene_.pixelCount();
  if (plan.techniqueCount != scene_.techniqueCount() || plan.counts.size() != size_t(pixels) * plan.techniqueCount ||
      plan.firstIndex.size() != plan.counts.size())
    throw std::logic_error("stage plan does not match the scene");
  return runPixels(plan, seed, takeSlots(plan), PixelRange{0, pixels});
}

void StageSampler::reset() {
  taken_ = searched_ = 0;
  closed_ = false;
  forgetStages();
}

std::vector<float> emptyStoredSamples(const Scene& scene, int capacity) {
  const int M = scene.techniqueCount();
  std::vector<float> samples(paddedPixelCount(size_t(scene.pixelCount())) * size_t(capacity) * size_t(M + 2), 1.0f);
  for (size_t record = 0; record < samples.size() / 16; ++record) {
    int q = int(record % size_t(M + 2));
    if (q < 2) std::fill_n(samples.begin() + record * 16, 16, 0.0f);
  }
  return samples;
}

bool keepsStatistics(const SamplerConfig& config) { return config.statsMask != 0 || config.sampleCapacity > 0; }

SamplerConfig plainConfig(SamplerConfig config) {
  config.statsMask = 0;
  config.sampleCapacity = 0;
  config.gridSize = 0;
  return config;
}

}  // namespace misalloc
