#pragma once
// Constants that host code shares: one definition each. The kernels' float versions
// are in kernels/common.h (MA_PI, luminance) and stay equal to these.
#include <cstddef>

namespace misalloc {

inline constexpr double kPi = 3.14159265358979323846;

// Rec. 709 luminance of linear RGB, the colour space of the maps
// (data/envmaps/README.md): the envmap sampler's weights, the error metrics and the
// tests. kernels/common.h's luminance() uses the same weights in float.
inline constexpr double kLuminanceR = 0.2126, kLuminanceG = 0.7152, kLuminanceB = 0.0722;
constexpr double luminance(double r, double g, double b) { return kLuminanceR * r + kLuminanceG * g + kLuminanceB * b; }

// The kernels lay per-pixel buffers out in blocks of 16 pixels (the stored samples of
// kernels/stats.h, storedSampleIndex; the grid search's work-items, one per block in
// kernels/gridsearch.cl): buffers hold a whole number of blocks.
inline constexpr int kPixelBlock = 16;
constexpr std::size_t paddedPixelCount(std::size_t pixels) {
  return (pixels + kPixelBlock - 1) / kPixelBlock * kPixelBlock;
}

}  // namespace misalloc
