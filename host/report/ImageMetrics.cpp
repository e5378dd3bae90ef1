#include "report/ImageMetrics.h"

#include <fmt/format.h>

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
    double d = double(image.rgb[i]) - reference.rgb[i];
    sum += d * d;
  }
  return std::sqrt(sum / double(image.rgb.size()));
}

double relativeMse(const RgbImage& image, const RgbImage& reference) {
  checkSameSize(image, reference);
  constexpr double epsilon = 0.01;
  double sum = 0;
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    double r = reference.rgb[i], d = double(image.rgb[i]) - r;
    sum += d * d / (r * r + epsilon);
  }
  return sum / double(image.rgb.size());
}

}  // namespace misalloc
