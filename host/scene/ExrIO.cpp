#include "scene/ExrIO.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfTestFile.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "AtomicFile.h"
#include "Error.h"
#include "MemoryBudget.h"

namespace misalloc {
namespace {

constexpr char kRgbNames[3] = {'R', 'G', 'B'};

TexelLocation locationOf(std::size_t valueIndex, int width) {
  std::size_t pixel = valueIndex / 3;
  return {int(pixel % std::size_t(width)), int(pixel / std::size_t(width)), kRgbNames[valueIndex % 3]};
}

// isOpenExrFile checks the magic number, so a wrong file type gets its own message
// instead of whatever OpenEXR says about the bytes it tried to parse.
void requireOpenExrFile(const std::string& path) {
  std::error_code ignored;
  if (!std::filesystem::exists(path, ignored)) throw InputError(fmt::format("'{}': no such file", path));
  if (!Imf::isOpenExrFile(path.c_str()))
    throw InputError(fmt::format("'{}' is not an OpenEXR file (or cannot be read)", path));
}

std::string channelNames(const Imf::ChannelList& channels) {
  std::string names;
  for (auto c = channels.begin(); c != channels.end(); ++c)
    names += (names.empty() ? "" : ", ") + std::string(c.name());
  return names.empty() ? "none" : names;
}

void requireRgbChannels(const Imf::Header& header, const std::string& path) {
  for (char name : kRgbNames) {
    const Imf::Channel* channel = header.channels().findChannel(std::string(1, name));
    if (!channel)
      throw InputError(fmt::format("'{}' has no {} channel: an RGB image needs R, G and B (channels found: {})", path,
                                   name, channelNames(header.channels())));
    // A subsampled channel has fewer values than pixels; resampling it is not our job.
    if (channel->xSampling != 1 || channel->ySampling != 1)
      throw InputError(fmt::format("'{}': channel {} is subsampled, which is not supported", path, name));
  }
}

RgbImage readRgbPixels(const std::string& path) {
  // The constructor rejects an empty or overflowing data window ("Invalid data
  // window in image header"), so its width and height fit an int and are ≥ 1.
  Imf::InputFile file(path.c_str());
  requireRgbChannels(file.header(), path);
  const Imath::Box2i& window = file.header().dataWindow();
  RgbImage image;
  image.width = window.max.x - window.min.x + 1;
  image.height = window.max.y - window.min.y + 1;
  requireHostMemory(fmt::format("'{}' ({}×{} texels × 12 B)", path, image.width, image.height),
                    double(image.width) * image.height * 3 * sizeof(float));
  image.rgb.resize(std::size_t(image.width) * std::size_t(image.height) * 3);
  const std::size_t pixelBytes = 3 * sizeof(float);
  Imf::FrameBuffer frame;
  for (int c = 0; c < 3; ++c)
    frame.insert(std::string(1, kRgbNames[c]), Imf::Slice::Make(Imf::FLOAT, image.rgb.data() + c, window, pixelBytes,
                                                                pixelBytes * std::size_t(image.width)));
  file.setFrameBuffer(frame);
  file.readPixels(window.min.y, window.max.y);
  return image;
}

void rejectNonFinite(const RgbImage& image, const std::string& path) {
  std::size_t count = 0, first = 0;
  for (std::size_t i = 0; i < image.rgb.size(); ++i)
    if (!std::isfinite(image.rgb[i]) && count++ == 0) first = i;
  if (count > 0)
    throw InputError(fmt::format("'{}' has {} NaN or infinite channel values, the first at {}", path, count,
                                 toString(locationOf(first, image.width))));
}

void zeroNegatives(RgbImage& image, ReadWarnings* warnings) {
  ReadWarnings found;
  for (std::size_t i = 0; i < image.rgb.size(); ++i) {
    if (image.rgb[i] >= 0.0f) continue;
    if (found.negativeValues++ == 0) found.firstNegative = locationOf(i, image.width);
    image.rgb[i] = 0.0f;
  }
  if (warnings) *warnings = found;
}

// An OpenEXR output stream into memory: OpenEXR seeks back to fill in the line offset
// table, and the complete file then replaces the target in one step.
class MemoryOStream : public Imf::OStream {
 public:
  MemoryOStream() : Imf::OStream("memory") {}

  void write(const char c[], int n) override {
    if (position_ + std::size_t(n) > bytes_.size()) bytes_.resize(position_ + std::size_t(n));
    std::memcpy(&bytes_[position_], c, std::size_t(n));
    position_ += std::size_t(n);
  }
  uint64_t tellp() override { return position_; }
  void seekp(uint64_t position) override { position_ = std::size_t(position); }

  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
  std::size_t position_ = 0;
};

std::string encode(const Imf::Header& header, const Imf::FrameBuffer& frame) {
  MemoryOStream stream;
  {
    Imf::OutputFile file(stream, header);
    file.setFrameBuffer(frame);
    file.writePixels(header.dataWindow().max.y - header.dataWindow().min.y + 1);
  }  // the destructor writes the line offset table
  return stream.bytes();
}

// A written image is always finite: an overflow upstream is a bug to report, not a
// file to leave for the next tool to trip on.
void requireFinite(const float* values, std::size_t count, const std::string& what) {
  std::size_t bad = 0;
  for (std::size_t i = 0; i < count; ++i) bad += std::isfinite(values[i]) ? 0 : 1;
  if (bad > 0) throw std::runtime_error(fmt::format("{} holds {} NaN or infinite values; not written", what, bad));
}

Imf::Header floatHeader(int width, int height, const std::vector<std::string>& names) {
  if (width <= 0 || height <= 0) throw std::invalid_argument(fmt::format("EXR size {}×{} is empty", width, height));
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  return header;
}

}  // namespace

std::string toString(const TexelLocation& location) {
  return fmt::format("x={}, y={}, channel {}", location.x, location.y, location.channel);
}

RgbImage readExr(const std::string& path, ReadWarnings* warnings) {
  requireOpenExrFile(path);
  RgbImage image;
  try {
    image = readRgbPixels(path);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {  // Iex::BaseExc for truncated or corrupt files
    throw InputError(fmt::format("cannot read '{}' (truncated or corrupt?): {}", path, e.what()));
  }
  rejectNonFinite(image, path);
  zeroNegatives(image, warnings);
  return image;
}

std::string encodeExr(const RgbImage& image) {
  if (image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3)
    throw std::invalid_argument(
        fmt::format("RgbImage {}×{} holds {} floats, not 3 per pixel", image.width, image.height, image.rgb.size()));
  Imf::Header header = floatHeader(image.width, image.height, {"R", "G", "B"});
  const std::size_t pixelBytes = 3 * sizeof(float);
  Imf::FrameBuffer frame;
  for (int c = 0; c < 3; ++c)
    frame.insert(std::string(1, kRgbNames[c]), Imf::Slice::Make(Imf::FLOAT, image.rgb.data() + c, header.dataWindow(),
                                                                pixelBytes, pixelBytes * std::size_t(image.width)));
  requireFinite(image.rgb.data(), image.rgb.size(), fmt::format("the {}×{} image", image.width, image.height));
  return encode(header, frame);
}

void writeExr(const std::string& path, const RgbImage& image) { writeFileAtomically(path, encodeExr(image)); }

std::string encodeExrChannels(int width, int height, const std::vector<std::string>& names,
                              const std::vector<std::vector<float>>& planes) {
  if (names.empty() || names.size() != planes.size())
    throw std::invalid_argument(fmt::format("{} channel names for {} planes", names.size(), planes.size()));
  if (std::set<std::string>(names.begin(), names.end()).size() != names.size())
    throw std::invalid_argument("EXR channel names must be distinct");
  Imf::Header header = floatHeader(width, height, names);
  Imf::FrameBuffer frame;
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (planes[k].size() != std::size_t(width) * std::size_t(height))
      throw std::invalid_argument(
          fmt::format("plane '{}' holds {} values, not {}×{}", names[k], planes[k].size(), width, height));
    requireFinite(planes[k].data(), planes[k].size(), fmt::format("channel '{}'", names[k]));
    frame.insert(names[k], Imf::Slice::Make(Imf::FLOAT, planes[k].data(), header.dataWindow()));
  }
  return encode(header, frame);
}

void writeExrChannels(const std::string& path, int width, int height, const std::vector<std::string>& names,
                      const std::vector<std::vector<float>>& planes) {
  writeFileAtomically(path, encodeExrChannels(width, height, names, planes));
}

}  // namespace misalloc
