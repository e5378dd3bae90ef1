#pragma once
#include "scene/ExrIO.h"

namespace misalloc {

// Every error is over the pixels that `image` covers (RgbImage::alpha): the background
// takes no samples and counts in no error.

// Root mean squared error over all pixels and RGB channels ([HS14] Table 5.2 reports
// it ×1000).
double rmse(const RgbImage& image, const RgbImage& reference);

// Mean over pixels and channels of (x − r)² / (r² + ε), ε = 0.01: the relative MSE
// of Rousselle et al. 2011; ε keeps it defined where the true value is 0.
double relativeMse(const RgbImage& image, const RgbImage& reference);

// The MSE against the true image, measured against a sampled reference r whose own
// error has the standard deviation `referenceError` (per pixel and channel, as rgb;
// empty for an exact reference): for r independent of x, E[(x − r)²] = E[(x − I)²] +
// Var(r), so the mean of (x − r)² − Var(r) is unbiased. Its standard error is that of
// the mean of the pixels' terms, the pixels being independent estimates.
struct CorrectedMse {
  double mse = 0, standardError = 0;
};
CorrectedMse correctedMse(const RgbImage& image, const RgbImage& reference, const std::vector<float>& referenceError);

// Throws InputError unless both images have the same size.
void checkSameSize(const RgbImage& image, const RgbImage& reference);

}  // namespace misalloc
