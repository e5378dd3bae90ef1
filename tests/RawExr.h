#pragma once
// An EXR file with whatever values a test needs, NaN and Inf included, which
// misalloc's own writers refuse to write.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMatrixAttribute.h>
#include <ImfOutputFile.h>

#include <array>
#include <map>
#include <string>
#include <vector>

#include "scene/ExrIO.h"

namespace misalloc::test {

inline void writeRawExr(const std::string& path, const RgbImage& image) {
  Imf::Header header(image.width, image.height);
  const char* names[3] = {"R", "G", "B"};
  for (const char* name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  const size_t pixelBytes = 3 * sizeof(float);
  Imf::FrameBuffer frame;
  for (int c = 0; c < 3; ++c)
    frame.insert(names[c],
                 Imf::Slice(Imf::FLOAT, (char*)(image.rgb.data() + c), pixelBytes, pixelBytes * size_t(image.width)));
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(image.height);
}

// Named float planes (a G-buffer), with 4×4 matrix attributes stored as given, row by row
// (as pbrt-v4 stores its worldToCamera).
inline void writeRawChannels(const std::string& path, int width, int height, const std::vector<std::string>& names,
                             const std::vector<std::vector<float>>& planes,
                             const std::map<std::string, std::array<float, 16>>& matrices = {}) {
  Imf::Header header(width, height);
  for (const auto& name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  for (const auto& [name, m] : matrices)
    header.insert(name, Imf::M44fAttribute(Imath::M44f(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], m[9],
                                                       m[10], m[11], m[12], m[13], m[14], m[15])));
  Imf::FrameBuffer frame;
  for (size_t k = 0; k < names.size(); ++k)
    frame.insert(names[k],
                 Imf::Slice(Imf::FLOAT, (char*)planes[k].data(), sizeof(float), sizeof(float) * size_t(width)));
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(height);
}

}  // namespace misalloc::test
