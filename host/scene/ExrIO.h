#pragma once
// Reading and writing scanline OpenEXR images as 32-bit float channels.
#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace misalloc {

// Linear RGB radiance, 3 floats per pixel, row-major, row 0 (the top) first; with
// coverage, an alpha per pixel: 1 where a surface is seen, 0 for the background, whose
// RGB is 0 (transparent black). Without it every pixel is covered.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;
  std::vector<float> alpha;  // empty, or one value per pixel (the EXR's A channel)

  bool covers(std::size_t pixel) const { return alpha.empty() || alpha[pixel] > 0; }
  std::size_t coveredPixels() const;
};

// One channel value of an image: column x, row y (0 = top), channel 'R', 'G' or 'B'.
struct TexelLocation {
  int x = 0, y = 0;
  char channel = 'R';
};

// "x=12, y=3, channel G", for messages.
std::string toString(const TexelLocation& location);

// What readExr repaired: negative channel values (not radiance, but left by some
// filters and HDR merges) are set to 0 so the caller can warn instead of failing.
struct ReadWarnings {
  std::size_t negativeValues = 0;
  TexelLocation firstNegative;  // meaningful when negativeValues > 0
};

// String attributes of an EXR header, by name: what a file says about itself.
using ExrAttributes = std::map<std::string, std::string>;

// Reads the R, G and B channels of `path` as float, whatever their stored type
// (half, float or uint), and its A channel where it has one; any other channel is ignored. The image is the
// display window, the rectangle the file's pixels stand for (for an envmap, the whole
// sphere): its texels outside the data window are black, and data outside it is
// left out. Throws InputError, naming the file, if it is missing, not an OpenEXR file,
// truncated or corrupt, lacks R, G or B, has an empty window, or holds NaN or infinite
// values. `attributes`, if given, receives the header's string attributes.
RgbImage readExr(const std::string& path, ReadWarnings* warnings = nullptr, ExrAttributes* attributes = nullptr);

// What readExr checks of every image it reads, for images given in memory (the Python
// module's arrays): throws InputError naming `source` for NaN or infinite values, or an
// alpha outside [0, 1], and sets negative values to 0, counting them in `warnings`.
void checkImageValues(RgbImage& image, const std::string& source, ReadWarnings* warnings = nullptr);

// The bytes of an OpenEXR file of float R, G, B (and A with coverage) with ZIP compression, with `attributes`
// in its header. Both encoders refuse (std::runtime_error) values that are NaN or
// infinite: a written image is always finite.
std::string encodeExr(const RgbImage& image, const ExrAttributes& attributes = {});

// Writes encodeExr's bytes through writeFileAtomically, so a failure (InputError)
// never leaves a partial file or damages an existing one.
void writeExr(const std::string& path, const RgbImage& image);

// One float channel per plane (width × height values, row 0 first), named by
// `names`, e.g. per-pixel allocation maps, with `attributes` in the header.
std::string encodeExrChannels(int width, int height, const std::vector<std::string>& names,
                              const std::vector<std::vector<float>>& planes, const ExrAttributes& attributes = {});

// The channels `names` of a file encodeExrChannels wrote, one plane each over its data
// window. Throws InputError naming the file if it cannot be read or lacks a channel.
std::vector<std::vector<float>> readExrChannels(const std::string& path, const std::vector<std::string>& names);

// What the header of `path` says: its data window's size, its channels' names, and its
// 4×4 float matrix attributes by name, their 16 values in the order stored (pbrt-v4
// stores its matrices row by row, for column vectors: p' = M p). Throws InputError
// naming the file if it cannot be read.
struct ExrHeader {
  int width = 0, height = 0;
  std::vector<std::string> channels;
  std::map<std::string, std::array<float, 16>> matrices;
};
ExrHeader readExrHeader(const std::string& path);

// Writes encodeExrChannels's bytes through writeFileAtomically.
void writeExrChannels(const std::string& path, int width, int height, const std::vector<std::string>& names,
                      const std::vector<std::vector<float>>& planes);

}  // namespace misalloc
