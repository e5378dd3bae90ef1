#pragma once
#include <string>

#include "scene/ExrIO.h"

namespace misalloc {

// The factor that maps `reference`'s 99th-percentile channel value to 1, so that the
// previews of one scene share an exposure and their noise can be compared by eye.
double previewExposure(const RgbImage& reference);

// The PNG bytes of an 8-bit sRGB preview of a linear image scaled by `exposure`,
// clipped to [0, 1].
std::string encodePreviewPng(const RgbImage& image, double exposure);
void writePreviewPng(const std::string& path, const RgbImage& image, double exposure);

// The preview's file beside an EXR: the same name with .png.
std::string previewPath(const std::string& exrPath);

}  // namespace misalloc
