#include "report/ImageMetrics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "Error.h"

namespace misalloc {

void checkSameSize(const RgbImage& image, const RgbImage& reference) {
  if (image.width != reference.width || image.height != reference.height)
    throw InputError(fmt::format("the reference is {}x{}, the image {}x{}", reference.width, reference.height,
                                 image.width, image.height));
}

double rmse(const RgbImage& image, const RgbImage& reference) {
  checkSameSize(image, reference);
  double sum = 0;
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    if (!image.covers(i / 3)) continue;
    double d = double(image.rgb[i]) - reference.rgb[i];
    sum += d * d;
  }
  return std::sqrt(sum / double(3 * image.coveredPixels()));
}

CorrectedMse correctedMse(const RgbImage& image, const RgbImage& reference, const std::vector<float>& referenceError) {
  checkSameSize(image, reference);
  const size_t pixels = image.coveredPixels();
  double sum = 0, sumSquares = 0;
  for (size_t p = 0; p < image.rgb.size() / 3; ++p) {
    if (!image.covers(p)) continue;
    double term = 0;
    for (size_t i = 3 * p; i < 3 * p + 3; ++i) {
      const double d = double(image.rgb[i]) - reference.rgb[i];
      const double e = referenceError.empty() ? 0.0 : referenceError[i];
      term += d * d - e * e;
    }
    term /= 3;
    sum += term;
    sumSquares += term * term;
  }
  const double mean = sum / double(pixels);
  const double spread = pixels > 1 ? std::max(0.0, (sumSquares - pixels * mean * mean) / double(pixels - 1)) : 0.0;
  return {mean, std::sqrt(spread / double(pixels))};
}

double relativeMse(const RgbImage& image, const RgbImage& reference) {
  checkSameSize(image, reference);
  constexpr double epsilon = 0.01;
  double sum = 0;
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    if (!image.covers(i / 3)) continue;
    double r = reference.rgb[i], d = double(image.rgb[i]) - r;
    sum += d * d / (r * r + epsilon);
  }
  return sum / double(3 * image.coveredPixels());
}

}  // namespace misalloc
