#pragma once
// The pictures misalloc writes, decoded and held to what their writers document: a
// preview is its image in 8-bit sRGB at an exposure, clipped to [0, 1]
// (report/PreviewPng.h); an α map is an EXR of one plane per technique, on the simplex
// where a surface is seen and 0 on the background, and a picture of its envmap share in
// blue and the rest in red, the background black (report/AlphaMap.h).
#include <png.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "scene/ExrIO.h"

namespace misalloc::test {

struct Picture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // 3 bytes per pixel, row 0 (the top) first
};

// An 8-bit PNG's bytes as RGB, through libpng's simplified API.
inline Picture decodePng(const std::string& bytes) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  REQUIRE(png_image_begin_read_from_memory(&image, bytes.data(), bytes.size()) != 0);
  image.format = PNG_FORMAT_RGB;
  Picture picture{int(image.width), int(image.height), std::vector<uint8_t>(PNG_IMAGE_SIZE(image))};
  REQUIRE(png_image_finish_read(&image, nullptr, picture.rgb.data(), 0, nullptr) != 0);
  return picture;
}

inline Picture readPng(const std::filesystem::path& path) {
  INFO(path.string());
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in);
  return decodePng(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
}

// The sRGB transfer function (IEC 61966-2-1) and its inverse.
inline double srgbEncode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}
inline double srgbDecode(double encoded) {
  return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

// The channel bytes of `preview` more than one 8-bit step from `image` at `exposure`: the
// writer rounds to the nearest step, and the step of slack absorbs its float rounding.
inline size_t previewMismatches(const Picture& preview, const RgbImage& image, double exposure) {
  REQUIRE(preview.rgb.size() == image.rgb.size());
  size_t bad = 0;
  for (size_t i = 0; i < image.rgb.size(); ++i)
    bad += std::abs(preview.rgb[i] - 255 * srgbEncode(std::clamp(exposure * image.rgb[i], 0.0, 1.0))) > 1;
  return bad;
}

// The exposures at which every byte of the previews seen so far is within one step of its
// image: previews that share an exposure narrow one range each, and leave it empty
// (lo > hi) when no single exposure draws them all.
struct ExposureRange {
  double lo = 0, hi = HUGE_VAL;
  bool empty() const { return lo > hi; }
};

inline void narrowExposure(ExposureRange& range, const Picture& preview, const RgbImage& image) {
  REQUIRE(preview.rgb.size() == image.rgb.size());
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    const double v = image.rgb[i], b = preview.rgb[i];
    if (!(v > 0)) {  // black at any exposure
      if (b > 1) range.lo = HUGE_VAL;
      continue;
    }
    // 255 srgbEncode(e v) within [b − 1, b + 1]; at 255 it may be clipped from above.
    if (b > 1) range.lo = std::max(range.lo, srgbDecode((b - 1) / 255) / v);
    if (b < 255) range.hi = std::min(range.hi, srgbDecode(std::min(b + 1, 255.0) / 255) / v);
  }
}

// An α map's EXR: its size and channels (alpha.<technique>) checked, its planes in the
// order of `techniques`, the scene's.
inline std::vector<std::vector<float>> readAlphaMap(const std::string& path, const std::vector<std::string>& techniques,
                                                    int width, int height) {
  const ExrHeader header = readExrHeader(path);
  CHECK(header.width == width);
  CHECK(header.height == height);
  std::vector<std::string> names, channels = header.channels;
  for (const std::string& t : techniques) names.push_back("alpha." + t);
  std::vector<std::string> sorted = names;
  std::sort(sorted.begin(), sorted.end());
  std::sort(channels.begin(), channels.end());
  CHECK(channels == sorted);
  return readExrChannels(path, names);
}

// An α map's planes against the image rendered with them: each technique's mean over the
// covered pixels, and the pixels whose α do not sum to 1 where a surface is seen, or are
// not all 0 on the background (which took no samples).
struct AlphaSummary {
  std::vector<double> coveredMean;
  size_t offSimplex = 0;
};

inline AlphaSummary summarizeAlpha(const std::vector<std::vector<float>>& planes, const RgbImage& image) {
  const size_t pixels = image.rgb.size() / 3;
  AlphaSummary s{std::vector<double>(planes.size(), 0.0), 0};
  for (size_t p = 0; p < pixels; ++p) {
    double sum = 0;
    bool negative = false;
    for (const std::vector<float>& plane : planes) sum += plane[p], negative |= plane[p] < 0;
    if (!image.covers(p)) {
      s.offSimplex += sum != 0;
      continue;
    }
    s.offSimplex += negative || std::abs(sum - 1) > 1e-6;  // float planes of double α
    for (size_t k = 0; k < planes.size(); ++k) s.coveredMean[k] += planes[k][p] / double(image.coveredPixels());
  }
  return s;
}

// The pixels of an α map's picture not drawn from its envmap plane: red 255 (1 − α),
// green 0 and blue 255 α where a surface is seen, black on the background.
inline size_t alphaPictureMismatches(const Picture& picture, const std::vector<float>& envmap, const RgbImage& image) {
  REQUIRE(picture.rgb.size() == image.rgb.size());
  size_t bad = 0;
  for (size_t p = 0; p < envmap.size(); ++p) {
    const double a = image.covers(p) ? envmap[p] : 0, on = image.covers(p) ? 1 : 0;
    const uint8_t* px = &picture.rgb[3 * p];
    bad += std::abs(px[0] - 255 * on * (1 - a)) > 1 || px[1] != 0 || std::abs(px[2] - 255 * a) > 1;
  }
  return bad;
}

}  // namespace misalloc::test
