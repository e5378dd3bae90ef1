#pragma once
// The sampler's running sums and stored samples (kernels/stats.h) read back as the
// allocation rules' per-pixel inputs (host/stats/PixelStats.h, PixelSamples.h).
#include <vector>

#include "stats/PixelSamples.h"
#include "stats/PixelStats.h"

namespace misalloc {

// One pixel's sums, `slots` the kernel's slots for that pixel.
PixelStats decodePixelStats(const double* slots, unsigned mask, int techniqueCount);

// One pixel's first `taken` stored samples.
PixelSamples decodePixelSamples(const std::vector<float>& stored, int pixel, int taken, int capacity,
                                int techniqueCount);

}  // namespace misalloc
