#pragma once
#include <mutex>
#include <optional>
#include <vector>

#include "sampling/Stage.h"

namespace misalloc {

// Hands out one stage's pixels in tiles to devices that pull the next tile when they
// finish one (guided self-scheduling). A device's tile is its share, by measured rate,
// of half the time the remaining pixels are expected to take, so tiles shrink as the
// stage ends and every device finishes within about one small tile of the others.
// Thread-safe.
class TileQueue {
 public:
  // `rates`: pixels per second of each device, 0 where not yet measured. Tiles are
  // whole multiples of `granularity` pixels, but for the image's last.
  TileQueue(int pixels, std::vector<double> rates, int granularity);

  // The device's next tile, or nothing when every pixel is handed out.
  std::optional<PixelRange> next(int device);
  // A tile took `seconds` on `device`: its rate becomes what that tile measured.
  void finished(int device, PixelRange tile, double seconds);
  // A device failed: its tiles go to the others, and it gets no more.
  void giveBack(PixelRange tile);
  void retire(int device);

  std::vector<double> rates() const;
  // Every pixel handed out and none given back.
  bool drained() const;

 private:
  int tileSize(int device) const;  // with mutex_ held

  mutable std::mutex mutex_;
  const int pixels_, granularity_;
  int cursor_ = 0;                     // pixels [0, cursor_) are handed out, but for givenBack_
  std::vector<PixelRange> givenBack_;  // handed out first
  std::vector<double> rates_;
  std::vector<unsigned char> retired_;
};

}  // namespace misalloc
