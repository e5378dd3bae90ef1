#include "report/PreviewPng.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "AtomicFile.h"

#include "scene/PngIO.h"

namespace misalloc {
namespace {

// The sRGB transfer function (IEC 61966-2-1).
double srgbEncode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}

}  // namespace

double previewExposure(const RgbImage& reference) {
  std::vector<float> values;
  for (float v : reference.rgb)
    if (std::isfinite(v) && v > 0) values.push_back(v);
  if (values.empty()) return 1;
  auto p99 = values.begin() + std::ptrdiff_t(0.99 * double(values.size() - 1));
  std::nth_element(values.begin(), p99, values.end());
  return 1 / double(*p99);
}

std::string encodePreviewPng(const RgbImage& image, double exposure) {
  std::vector<uint8_t> rgb(image.rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    double v = std::isfinite(image.rgb[i]) ? std::clamp(exposure * image.rgb[i], 0.0, 1.0) : 1.0;
    rgb[i] = uint8_t(std::lround(255 * srgbEncode(v)));
  }
  return encodePng(image.width, image.height, rgb);
}

void writePreviewPng(const std::string& path, const RgbImage& image, double exposure) {
  writeFileAtomically(path, encodePreviewPng(image, exposure));
}

std::string previewPath(const std::string& exrPath) {
  return std::filesystem::path(exrPath).replace_extension(".png").string();
}

}  // namespace misalloc
