#include "sampling/TiledSampler.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>

#include "Constants.h"
#include "Error.h"
#include "sampling/TileQueue.h"

namespace misalloc {
namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// The stored samples of the pixel blocks that `tile` covers: tiles start on a block
// (TileQueue granularity kPixelBlock), so blocks are never shared between tiles.
std::pair<size_t, size_t> storedSpan(PixelRange tile, int capacity, int columns) {
  const size_t blockFloats = size_t(capacity) * size_t(MA_SAMPLE_RECORD_FLOATS(columns)) * kPixelBlock;
  const size_t firstBlock = size_t(tile.begin) / kPixelBlock;
  const size_t endBlock = (size_t(tile.end) + kPixelBlock - 1) / kPixelBlock;
  return {firstBlock * blockFloats, endBlock * blockFloats};
}

}  // namespace

TiledSampler::TiledSampler(const Scene& scene, const SamplerConfig& config,
                           std::vector<std::unique_ptr<StageSampler>> members)
    : StageSampler(scene, config),
      members_(std::move(members)),
      sampleRates_(members_.size(), 0.0),
      failures_(members_.size()) {
  if (members_.empty()) throw std::invalid_argument("TiledSampler without devices");
  forgetStages();
}

std::string TiledSampler::launchIdentity() const {
  std::string identity = "tiles over";
  for (const auto& member : members_) identity += " [" + member->launchIdentity() + "]";
  return identity;
}

StageResult TiledSampler::runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) {
  const int M = scene_.techniqueCount();
  const size_t D = members_.size();
  StageResult out;
  out.rgb.assign(size_t(range.size()) * 3, 0.0);
  out.moments.assign(size_t(range.size()) * M * 2, 0.0);
  std::vector<double> pixelRates(D);
  for (size_t d = 0; d < D; ++d) pixelRates[d] = sampleRates_[d] / std::max(1, plan.stageSamples);
  TileQueue queue(range.size(), pixelRates, kPixelBlock);
  for (size_t d = 0; d < D; ++d)
    if (!live(d)) queue.retire(int(d));
  // The running sums of a stage that keeps them live on the member that ran the tile
  // until gatherStatistics: a member that fails loses every tile it ran.
  const bool losesTiles = plan.keepStatistics && keepsStatistics(config_);
  if (losesTiles) loadMembers(members_.size());
  std::vector<std::vector<PixelRange>> ran(D);
  std::vector<Clock::time_point> lastFinish(D);
  std::exception_ptr programmingError;  // not a device's failure: rethrown as it is
  std::mutex errorMutex;
  const Clock::time_point start = Clock::now();

  auto work = [&](size_t d) {
    while (std::optional<PixelRange> tile = queue.next(int(d))) {
      const PixelRange pixels{range.begin + tile->begin, range.begin + tile->end};
      const Clock::time_point launched = Clock::now();
      StageResult r;
      try {
        r = members_[d]->runPixels(plan, seed, firstSlot, pixels);
      } catch (const cl::Error& e) {
        failures_[d] = fmt::format("OpenCL error {} in {}", e.err(), e.what());
      } catch (const DeviceError& e) {
        failures_[d] = e.what();
      } catch (...) {
        std::lock_guard<std::mutex> lock(errorMutex);
        programmingError = std::current_exception();
        queue.retire(int(d));
        return;
      }
      if (!live(d)) {
        queue.retire(int(d));
        queue.giveBack(*tile);
        if (losesTiles)
          for (PixelRange lost : ran[d]) queue.giveBack(lost);
        ran[d].clear();
        return;
      }
      const Clock::time_point finished = Clock::now();
      queue.finished(int(d), *tile, seconds(launched, finished));
      std::copy(r.rgb.begin(), r.rgb.end(), out.rgb.begin() + size_t(tile->begin) * 3);
      std::copy(r.moments.begin(), r.moments.end(), out.moments.begin() + size_t(tile->begin) * M * 2);
      ran[d].push_back(pixels);
      lastFinish[d] = finished;
    }
  };

  // A member that fails late gives its tiles back after the others may have stopped
  // pulling: the survivors go round again until every tile has run.
  while (!queue.drained() && !programmingError) {
    std::vector<std::thread> threads;
    for (size_t d = 0; d < D; ++d)
      if (live(d)) threads.emplace_back(work, d);
    if (threads.empty())
      throw DeviceError(fmt::format(
          "every device failed; the first: {}",
          *std::find_if(failures_.begin(), failures_.end(), [](const std::string& f) { return !f.empty(); })));
    for (std::thread& t : threads) t.join();
  }
  if (programmingError) std::rethrow_exception(programmingError);

  std::vector<double> rates = queue.rates();
  Clock::time_point first = Clock::time_point::max(), last = start;
  for (size_t d = 0; d < D; ++d) {
    if (ran[d].empty()) continue;
    sampleRates_[d] = rates[d] * plan.stageSamples;
    first = std::min(first, lastFinish[d]);
    last = std::max(last, lastFinish[d]);
  }
  if (first != Clock::time_point::max()) imbalanceSeconds_ += seconds(first, last);
  out.kernelSeconds = seconds(start, last);
  if (losesTiles) gatherStatistics(ran);
  return out;
}

void TiledSampler::gatherStatistics(const std::vector<std::vector<PixelRange>>& ran) {
  const int slots = statSlots();
  for (size_t d = 0; d < members_.size(); ++d) {
    if (ran[d].empty()) continue;
    if (slots > 0) {
      const std::vector<double> stats = members_[d]->statistics();
      for (PixelRange t : ran[d])
        std::copy(stats.begin() + size_t(t.begin) * slots, stats.begin() + size_t(t.end) * slots,
                  stats_.begin() + size_t(t.begin) * slots);
    }
    if (config_.sampleCapacity > 0) {
      const std::vector<float> samples = members_[d]->storedSamples();
      for (PixelRange t : ran[d]) {
        auto [begin, end] = storedSpan(t, config_.sampleCapacity, sampleColumns(scene_, config_).count());
        std::copy(samples.begin() + begin, samples.begin() + end, samples_.begin() + begin);
      }
    }
  }
  std::fill(loaded_.begin(), loaded_.end(), 0);
}

void TiledSampler::loadMembers(size_t count) {
  for (size_t d = 0; d < count; ++d) {
    if (!live(d) || loaded_[d]) continue;
    if (!stats_.empty()) members_[d]->loadStatistics(stats_);
    if (!samples_.empty()) members_[d]->loadStoredSamples(samples_);
    loaded_[d] = 1;
  }
}

void TiledSampler::loadStatistics(const std::vector<double>& stats) {
  stats_ = stats;
  std::fill(loaded_.begin(), loaded_.end(), 0);
}

void TiledSampler::loadStoredSamples(const std::vector<float>& samples) {
  samples_ = samples;
  std::fill(loaded_.begin(), loaded_.end(), 0);
}

StoredSampleBuffer TiledSampler::storedSampleBuffer() {
  // The grid search's sums of earlier searches live on the first member's device.
  if (!live(0))
    throw DeviceError(
        fmt::format("{} runs the grid search and failed: {}", members_[0]->deviceShares().front().name, failures_[0]));
  loadMembers(1);
  return members_[0]->storedSampleBuffer();
}

int TiledSampler::launchGroupSize() const {
  int largest = 1;
  for (const auto& member : members_) largest = std::max(largest, member->launchGroupSize());
  return largest;
}

// Devices of different lanes (a CPU beside a GPU) are modelled by the widest.
int TiledSampler::pixelLanes(bool keepsStatistics) const {
  int widest = 0;
  for (const auto& member : members_) widest = std::max(widest, member->pixelLanes(keepsStatistics));
  return widest;
}

void TiledSampler::forgetStages() {
  for (size_t d = 0; d < members_.size(); ++d)
    if (live(d)) members_[d]->reset();
  loaded_.assign(members_.size(), 1);  // every member starts from zero sums, as stats_
  stats_.assign(size_t(scene_.pixelCount()) * statSlots(), 0.0);
  samples_ = config_.sampleCapacity > 0 ? emptyStoredSamples(scene_, config_) : std::vector<float>{};
  imbalanceSeconds_ = 0;
}

std::vector<DeviceShare> TiledSampler::deviceShares() const {
  std::vector<DeviceShare> shares;
  for (size_t d = 0; d < members_.size(); ++d) {
    DeviceShare share = members_[d]->deviceShares().front();
    share.failure = failures_[d];
    shares.push_back(share);
  }
  return shares;
}

}  // namespace misalloc
