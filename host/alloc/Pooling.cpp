#include "alloc/Pooling.h"

#include <algorithm>
#include <stdexcept>

namespace misalloc {
namespace {

// One separable pass: out[i] = Σ over the `radius` neighbours on either side along a
// line of `count` items, `stride` items apart, each item `channels` values.
void poolLine(const double* in, double* out, int count, std::size_t stride, int channels, int radius) {
  for (int i = 0; i < count; ++i) {
    double* o = out + i * stride;
    std::fill(o, o + channels, 0.0);
    for (int j = std::max(0, i - radius); j <= std::min(count - 1, i + radius); ++j) {
      const double* v = in + j * stride;
#pragma omp simd
      for (int c = 0; c < channels; ++c) o[c] += v[c];
    }
  }
}

}  // namespace

void poolNeighbourhood(std::vector<double>& values, int width, int height, int channels, int radius) {
  if (radius < 0) throw std::invalid_argument("poolNeighbourhood: negative radius");
  if (values.size() != std::size_t(width) * height * channels)
    throw std::invalid_argument("poolNeighbourhood: values do not match the image");
  if (radius == 0 || values.empty()) return;
  std::vector<double> rows(values.size());
  const std::size_t c = std::size_t(channels);
#pragma omp parallel for schedule(static)
  for (int y = 0; y < height; ++y)
    poolLine(values.data() + std::size_t(y) * width * c, rows.data() + std::size_t(y) * width * c, width, c, channels,
             radius);
#pragma omp parallel for schedule(static)
  for (int x = 0; x < width; ++x)
    poolLine(rows.data() + x * c, values.data() + x * c, height, std::size_t(width) * c, channels, radius);
}

}  // namespace misalloc
