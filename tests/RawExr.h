#pragma once
// An EXR file with whatever values a test needs, NaN and Inf included, which
// misalloc's own writers refuse to write.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <string>

#include "scene/ExrIO.h"

namespace misalloc::test {

inline void writeRawExr(const std::string& path, const RgbImage& image) {
  Imf::Header header(image.width, image.height);
  const char* names[3] = {"R", "G", "B"};
  for (const char* name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  const size_t pixelBytes = 3 * sizeof(float);
  Imf::FrameBuffer frame;
  for (int c = 0; c < 3; ++c)
    frame.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(image.rgb.data() + c), pixelBytes,
                                      pixelBytes * size_t(image.width)));
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(image.height);
}

}  // namespace misalloc::test
