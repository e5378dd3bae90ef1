#include "sampling/TileQueue.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace misalloc {
namespace {

// The first tile of a device not measured yet, in units of the granularity: small, so
// that a device 100× slower than the others holds them up for a moment only.
constexpr int kProbeTile = 4;

}  // namespace

TileQueue::TileQueue(int pixels, std::vector<double> rates, int granularity)
    : pixels_(pixels), granularity_(granularity), rates_(std::move(rates)), retired_(rates_.size(), 0) {
  if (pixels < 0 || granularity < 1 || rates_.empty()) throw std::invalid_argument("TileQueue: bad arguments");
}

int TileQueue::tileSize(int device) const {
  const int remaining = pixels_ - cursor_;
  const int devices = int(std::count(retired_.begin(), retired_.end(), 0));
  double known = 0;
  int measured = 0;
  for (size_t d = 0; d < rates_.size(); ++d)
    if (!retired_[d] && rates_[d] > 0) known += rates_[d], ++measured;
  double size;
  if (rates_[device] <= 0) {
    size = double(kProbeTile) * granularity_;
  } else {
    // Unmeasured devices are counted at the mean measured rate.
    const double total = known + (devices - measured) * known / measured;
    size = 0.5 * rates_[device] * remaining / total;
  }
  int tile = int(std::ceil(size / granularity_)) * granularity_;
  return std::clamp(tile, granularity_, std::max(remaining, granularity_));
}

std::optional<PixelRange> TileQueue::next(int device) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (retired_.at(device)) return std::nullopt;
  if (!givenBack_.empty()) {
    PixelRange tile = givenBack_.back();
    givenBack_.pop_back();
    return tile;
  }
  if (cursor_ >= pixels_) return std::nullopt;
  PixelRange tile{cursor_, std::min(pixels_, cursor_ + tileSize(device))};
  cursor_ = tile.end;
  return tile;
}

void TileQueue::finished(int device, PixelRange tile, double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (seconds > 0) rates_.at(device) = tile.size() / seconds;
}

void TileQueue::giveBack(PixelRange tile) {
  std::lock_guard<std::mutex> lock(mutex_);
  givenBack_.push_back(tile);
}

void TileQueue::retire(int device) {
  std::lock_guard<std::mutex> lock(mutex_);
  retired_.at(device) = 1;
}

bool TileQueue::drained() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cursor_ >= pixels_ && givenBack_.empty();
}

std::vector<double> TileQueue::rates() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rates_;
}

}  // namespace misalloc
