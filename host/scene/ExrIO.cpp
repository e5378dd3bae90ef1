#include "scene/ExrIO.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfMatrixAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfTestFile.h>
#include <fmt/format.h>

#include <algorithm>
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
// OpenEXR's own bound on a window's side, which keeps widths and products in range.
constexpr int kMaxWindowSide = 1 << 28;

TexelLocation locationOf(std::size_t valueIndex, int width) {
  std::size_t pixel = valueIndex / 3;
  return {int(pixel % std::size_t(width)), int(pixel / std::size_t(width)), kRgbNames[valueIndex % 3]};
}

// isOpenExrFile checks the magic number, so a wrong file type gets its own message
// instead of whatever OpenEXR says about the bytes it tried to parse.
void requireOpenExrFile(const std::string& path) {
  std::error_code ignored;
  if (!std::filesystem::exists(path, ignored)) throw InputError(fmt::format("'{}': no such file", path));
  // A FIFO or a device would block the open, or never end.
  if (!std::filesystem::is_regular_file(path, ignored))
    throw InputError(fmt::format("'{}' is not a regular file", path));
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

int widthOf(const Imath::Box2i& box) { return box.max.x - box.min.x + 1; }
int heightOf(const Imath::Box2i& box) { return box.max.y - box.min.y + 1; }

RgbImage blankImage(const Imath::Box2i& window, const std::string& path) {
  RgbImage image;
  image.width = widthOf(window);
  image.height = heightOf(window);
  requireHostMemory(fmt::format("'{}' ({}×{} texels × 12 B)", path, image.width, image.height),
                    double(image.width) * image.height * 3 * sizeof(float));
  image.rgb.assign(std::size_t(image.width) * std::size_t(image.height) * 3, 0.0f);
  return image;
}

// The data window's texels that lie in the display window, at their place in it; the
// rest transparent black where the image has coverage.
RgbImage placeInDisplayWindow(const RgbImage& data, const Imath::Box2i& dataWindow, const Imath::Box2i& display,
                              const std::string& path) {
  RgbImage image = blankImage(display, path);
  if (!data.alpha.empty()) image.alpha.assign(std::size_t(image.width) * std::size_t(image.height), 0.0f);
  const int x0 = std::max(dataWindow.min.x, display.min.x), x1 = std::min(dataWindow.max.x, display.max.x);
  for (int y = std::max(dataWindow.min.y, display.min.y); y <= std::min(dataWindow.max.y, display.max.y); ++y)
    for (int x = x0; x <= x1; ++x) {
      const std::size_t to = std::size_t(y - display.min.y) * image.width + std::size_t(x - display.min.x);
      const std::size_t from = std::size_t(y - dataWindow.min.y) * data.width + std::size_t(x - dataWindow.min.x);
      for (int c = 0; c < 3; ++c) image.rgb[3 * to + c] = data.rgb[3 * from + c];
      if (!data.alpha.empty()) image.alpha[to] = data.alpha[from];
    }
  return image;
}

RgbImage readRgbPixels(const std::string& path, ExrAttributes* attributes) {
  // The constructor rejects an empty or overflowing data window ("Invalid data
  // window in image header"), so its width and height fit an int and are ≥ 1.
  Imf::InputFile file(path.c_str());
  const Imf::Header& header = file.header();
  requireRgbChannels(header, path);
  const Imath::Box2i& window = header.dataWindow();
  const Imath::Box2i& display = header.displayWindow();
  if (widthOf(display) < 1 || heightOf(display) < 1 || widthOf(display) > kMaxWindowSide ||
      heightOf(display) > kMaxWindowSide)
    throw InputError(fmt::format("'{}': its display window is empty or too large", path));
  RgbImage image = blankImage(window, path);
  const std::size_t pixelBytes = 3 * sizeof(float);
  Imf::FrameBuffer frame;
  for (int c = 0; c < 3; ++c)
    frame.insert(std::string(1, kRgbNames[c]), Imf::Slice::Make(Imf::FLOAT, image.rgb.data() + c, window, pixelBytes,
                                                                pixelBytes * std::size_t(image.width)));
  if (header.channels().findChannel("A")) {
    image.alpha.assign(std::size_t(image.width) * std::size_t(image.height), 0.0f);
    frame.insert("A", Imf::Slice::Make(Imf::FLOAT, image.alpha.data(), window, sizeof(float),
                                       sizeof(float) * std::size_t(image.width)));
  }
  file.setFrameBuffer(frame);
  file.readPixels(window.min.y, window.max.y);
  if (attributes)
    for (auto a = header.begin(); a != header.end(); ++a)
      if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&a.attribute()))
        (*attributes)[a.name()] = text->value();
  return window == display ? image : placeInDisplayWindow(image, window, display, path);
}

void rejectNonFinite(const RgbImage& image, const std::string& path) {
  std::size_t count = 0, first = 0;
  for (std::size_t i = 0; i < image.rgb.size(); ++i)
    if (!std::isfinite(image.rgb[i]) && count++ == 0) first = i;
  if (count > 0)
    throw InputError(fmt::format("'{}' has {} NaN or infinite channel values, the first at {}", path, count,
                                 toString(locationOf(first, image.width))));
  for (std::size_t p = 0; p < image.alpha.size(); ++p)
    if (!(image.alpha[p] >= 0 && image.alpha[p] <= 1))
      throw InputError(fmt::format("'{}': its alpha at x={}, y={} is {}, not in [0, 1]", path,
                                   p % std::size_t(image.width), p / std::size_t(image.width), image.alpha[p]));
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

std::size_t RgbImage::coveredPixels() const {
  if (alpha.empty()) return std::size_t(width) * std::size_t(height);
  return std::size_t(std::count_if(alpha.begin(), alpha.end(), [](float a) { return a > 0; }));
}

std::string toString(const TexelLocation& location) {
  return fmt::format("x={}, y={}, channel {}", location.x, location.y, location.channel);
}

RgbImage readExr(const std::string& path, ReadWarnings* warnings, ExrAttributes* attributes) {
  requireOpenExrFile(path);
  RgbImage image;
  try {
    image = readRgbPixels(path, attributes);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {  // Iex::BaseExc for truncated or corrupt files
    throw InputError(fmt::format("cannot read '{}' (truncated or corrupt?): {}", path, e.what()));
  }
  checkImageValues(image, path, warnings);
  return image;
}

void checkImageValues(RgbImage& image, const std::string& source, ReadWarnings* warnings) {
  rejectNonFinite(image, source);
  zeroNegatives(image, warnings);
}

std::string encodeExr(const RgbImage& image, const ExrAttributes& attributes) {
  if (image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3)
    throw std::invalid_argument(
        fmt::format("RgbImage {}×{} holds {} floats, not 3 per pixel", image.width, image.height, image.rgb.size()));
  const bool coverage = !image.alpha.empty();
  if (coverage && image.alpha.size() != std::size_t(image.width) * std::size_t(image.height))
    throw std::invalid_argument(
        fmt::format("RgbImage {}×{} holds {} alpha values", image.width, image.height, image.alpha.size()));
  Imf::Header header =
      floatHeader(image.width, image.height,
                  coverage ? std::vector<std::string>{"R", "G", "B", "A"} : std::vector<std::string>{"R", "G", "B"});
  for (const auto& [name, value] : attributes) header.insert(name, Imf::StringAttribute(value));
  const std::size_t pixelBytes = 3 * sizeof(float);
  Imf::FrameBuffer frame;
  for (int c = 0; c < 3; ++c)
    frame.insert(std::string(1, kRgbNames[c]), Imf::Slice::Make(Imf::FLOAT, image.rgb.data() + c, header.dataWindow(),
                                                                pixelBytes, pixelBytes * std::size_t(image.width)));
  if (coverage)
    frame.insert("A", Imf::Slice::Make(Imf::FLOAT, image.alpha.data(), header.dataWindow(), sizeof(float),
                                       sizeof(float) * std::size_t(image.width)));
  requireFinite(image.rgb.data(), image.rgb.size(), fmt::format("the {}×{} image", image.width, image.height));
  return encode(header, frame);
}

void writeExr(const std::string& path, const RgbImage& image) { writeFileAtomically(path, encodeExr(image)); }

std::string encodeExrChannels(int width, int height, const std::vector<std::string>& names,
                              const std::vector<std::vector<float>>& planes, const ExrAttributes& attributes) {
  if (names.empty() || names.size() != planes.size())
    throw std::invalid_argument(fmt::format("{} channel names for {} planes", names.size(), planes.size()));
  if (std::set<std::string>(names.begin(), names.end()).size() != names.size())
    throw std::invalid_argument("EXR channel names must be distinct");
  Imf::Header header = floatHeader(width, height, names);
  for (const auto& [name, value] : attributes) header.insert(name, Imf::StringAttribute(value));
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

ExrHeader readExrHeader(const std::string& path) {
  requireOpenExrFile(path);
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    ExrHeader out;
    out.width = widthOf(header.dataWindow());
    out.height = heightOf(header.dataWindow());
    for (auto c = header.channels().begin(); c != header.channels().end(); ++c) out.channels.push_back(c.name());
    for (auto a = header.begin(); a != header.end(); ++a)
      if (const auto* m = dynamic_cast<const Imf::M44fAttribute*>(&a.attribute())) {
        std::array<float, 16>& values = out.matrices[a.name()];
        for (int i = 0; i < 16; ++i) values[size_t(i)] = m->value()[i / 4][i % 4];
      }
    return out;
  } catch (const std::exception& e) {
    throw InputError(fmt::format("cannot read '{}' (truncated or corrupt?): {}", path, e.what()));
  }
}

std::vector<std::vector<float>> readExrChannels(const std::string& path, const std::vector<std::string>& names) {
  requireOpenExrFile(path);
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i& window = file.header().dataWindow();
    const std::size_t width = std::size_t(widthOf(window)), values = width * std::size_t(heightOf(window));
    std::vector<std::vector<float>> planes(names.size(), std::vector<float>(values));
    Imf::FrameBuffer frame;
    for (std::size_t k = 0; k < names.size(); ++k) {
      if (!file.header().channels().findChannel(names[k]))
        throw InputError(fmt::format("'{}' has no channel {} (channels found: {})", path, names[k],
                                     channelNames(file.header().channels())));
      frame.insert(names[k],
                   Imf::Slice::Make(Imf::FLOAT, planes[k].data(), window, sizeof(float), sizeof(float) * width));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return planes;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(fmt::format("cannot read '{}' (truncated or corrupt?): {}", path, e.what()));
  }
}

}  // namespace misalloc
