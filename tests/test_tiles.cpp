// TileQueue (sampling/TileQueue.h): every pixel is handed out exactly once, whatever the
// devices' rates, failures and threads, and devices of unequal speed finish together.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <queue>
#include <thread>

#include "sampling/TileQueue.h"

using namespace misalloc;

namespace {

struct Simulation {
  std::vector<int> timesCovered;  // per pixel
  std::vector<double> finish;     // per device: when its last tile ended
  double end = 0;                 // when the last tile ended
  int tiles = 0;
};

// Devices of the given rates (pixels per second) pull tiles as they finish, each
// launch costing `launchSeconds` as well; events in time order. A device in `fails`
// fails at its second tile and gives it back, with the tiles it ran before.
Simulation simulate(int pixels, const std::vector<double>& rates, double launchSeconds, int failingDevice = -1) {
  const int D = int(rates.size());
  TileQueue queue(pixels, std::vector<double>(D, 0.0), 16);
  Simulation s{std::vector<int>(pixels, 0), std::vector<double>(D, 0.0)};
  std::vector<std::vector<PixelRange>> ran(D);
  using Event = std::pair<double, int>;  // (time the device is free, device)
  std::priority_queue<Event, std::vector<Event>, std::greater<>> free;
  for (int d = 0; d < D; ++d) free.push({0.0, d});
  std::vector<int> launches(D, 0);
  while (!free.empty()) {
    auto [t, d] = free.top();
    free.pop();
    std::optional<PixelRange> tile = queue.next(d);
    if (!tile) continue;
    if (d == failingDevice && ++launches[d] == 2) {
      queue.retire(d);
      queue.giveBack(*tile);
      for (PixelRange lost : ran[d]) {
        queue.giveBack(lost);
        for (int p = lost.begin; p < lost.end; ++p) --s.timesCovered[p];
      }
      // The others may have stopped pulling: wake them, as TiledSampler goes round again.
      for (int other = 0; other < D; ++other)
        if (other != d) free.push({t, other});
      continue;
    }
    const double seconds = launchSeconds + tile->size() / rates[d];
    queue.finished(d, *tile, seconds);
    for (int p = tile->begin; p < tile->end; ++p) ++s.timesCovered[p];
    ran[d].push_back(*tile);
    s.finish[d] = t + seconds;
    s.end = std::max(s.end, t + seconds);
    ++s.tiles;
    free.push({t + seconds, d});
  }
  CHECK(queue.drained());
  return s;
}

bool coveredOnce(const Simulation& s) {
  return std::all_of(s.timesCovered.begin(), s.timesCovered.end(), [](int n) { return n == 1; });
}

double imbalance(const Simulation& s, int skipDevice = -1) {
  double first = s.end;
  for (size_t d = 0; d < s.finish.size(); ++d)
    if (int(d) != skipDevice) first = std::min(first, s.finish[d]);
  return (s.end - first) / s.end;
}

}  // namespace

TEST_CASE("tiles cover every pixel exactly once and devices finish together", "[tiles]") {
  const std::vector<std::vector<double>> rateSets = {{1e5}, {1e5, 1e5}, {1e3, 1e5}, {1e5, 1e3}, {1e5, 2e5, 3e5, 4e5}};
  for (int pixels : {65536, 1000, 17, 1}) {
    for (const auto& rates : rateSets) {
      Simulation s = simulate(pixels, rates, 20e-6);
      INFO(fmt::format("{} pixels, rates {}", pixels, fmt::join(rates, ", ")));
      CHECK(coveredOnce(s));
      // A 256×256 image: the devices finish within 5 % of the render (the target),
      // a device 100× slower than the other included.
      if (pixels == 65536 && rates.size() > 1) CHECK(imbalance(s) <= 0.05);
    }
  }
}

TEST_CASE("a device that fails gives its tiles to the others", "[tiles]") {
  for (int failing : {0, 1}) {
    Simulation s = simulate(65536, {1e5, 3e5, 2e5}, 20e-6, failing);
    INFO("failing device " << failing);
    CHECK(coveredOnce(s));
    CHECK(imbalance(s, failing) <= 0.05);
  }
}

TEST_CASE("tile sizes follow the measured rates", "[tiles]") {
  TileQueue queue(100000, {1000.0, 3000.0}, 16);
  PixelRange slow = *queue.next(0), fast = *queue.next(1);
  CHECK(fast.size() > 2 * slow.size());
  CHECK(slow.begin % 16 == 0);
  CHECK(fast.begin % 16 == 0);
  CHECK(fast.size() % 16 == 0);
}

TEST_CASE("threads pulling at once take every tile exactly once", "[tiles]") {
  const int pixels = 50000;
  std::vector<std::atomic<int>> covered(pixels);
  TileQueue queue(pixels, {0.0, 0.0, 0.0, 0.0}, 16);
  std::vector<std::thread> threads;
  for (int d = 0; d < 4; ++d)
    threads.emplace_back([&, d] {
      while (std::optional<PixelRange> tile = queue.next(d)) {
        for (int p = tile->begin; p < tile->end; ++p) covered[p]++;
        queue.finished(d, *tile, 1e-6 * tile->size() * (d + 1));
      }
    });
  for (auto& t : threads) t.join();
  CHECK(std::all_of(covered.begin(), covered.end(), [](const std::atomic<int>& n) { return n == 1; }));
  CHECK(queue.drained());
}
