#pragma once
#include "scene/ExrIO.h"

namespace misalloc {

// Root mean squared error over all pixels and RGB channels ([HS14] Table 5.2 reports
// it ×1000).
double rmse(const RgbImage& image, const RgbImage& reference);

// Mean over pixels and channels of (x − r)² / (r² + ε), ε = 0.01: the relative MSE
// of Rousselle et al. 2011; ε keeps it defined where the true value is 0.
double relativeMse(const RgbImage& image, const RgbImage& reference);

// Throws InputError unless both images have the same size.
void checkSameSize(const RgbImage& image, const RgbImage& reference);

}  // namespace misalloc
