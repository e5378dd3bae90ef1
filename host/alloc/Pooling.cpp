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

// The window sums of each pixel over the pixels of its own surface, one by one: a
// surface's edge makes the window no box, which the separable passes need.
void poolWithinSurfaces(std::vector<double>& values, int width, int height, int channels, int radius,
                        const std::vector<int32_t>& surfaces) {
  const std::vector<double> in = values;
  const std::size_t c = std::size_t(channels);
#pragma omp parallel for schedule(static)
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t p = std::size_t(y) * width + x;
      double* o = values.data() + p * c;
      std::fill(o, o + channels, 0.0);
      for (int qy = std::max(0, y - radius); qy <= std::min(height - 1, y + radius); ++qy)
        for (int qx = std::max(0, x - radius); qx <= std::min(width - 1, x + radius); ++qx) {
          const std::size_t q = std::size_t(qy) * width + qx;
          if (surfaces[q] != surfaces[p]) continue;
          const double* v = in.data() + q * c;
#pragma omp simd
          for (int k = 0; k < channels; ++k) o[k] += v[k];
        }
    }
}

}  // namespace

void poolNeighbourhood(std::vector<double>& values, int width, int height, int channels, int radius,
                       const std::vector<int32_t>& surfaces) {
  if (radius < 0) throw std::invalid_argument("poolNeighbourhood: negative radius");
  if (values.size() != std::size_t(width) * height * channels ||
      !(surfaces.empty() || surfaces.size() == std::size_t(width) * height))
    throw std::invalid_argument("poolNeighbourhood: values do not match the image");
  if (radius == 0 || values.empty()) return;
  if (std::any_of(surfaces.begin(), surfaces.end(), [&](int32_t s) { return s != surfaces.front(); })) {
    poolWithinSurfaces(values, width, height, channels, radius, surfaces);
    return;
  }
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
