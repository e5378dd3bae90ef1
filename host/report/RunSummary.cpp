#include "report/RunSummary.h"

#include "report/ImageMetrics.h"

namespace misalloc {

RunSummary summarizeRun(const Rendering& r, int techniqueCount, const Reference* reference) {
  // Over the pixels the image covers: the background takes no samples.
  const size_t M = size_t(techniqueCount), pixels = r.image.coveredPixels();
  RunSummary s;
  s.meanAlpha.assign(M, 0.0);
  for (size_t p = 0; p < r.alpha.size() / M; ++p)
    for (size_t k = 0; k < M && r.image.covers(p); ++k) s.meanAlpha[k] += r.alpha[p * M + k] / double(pixels);
  s.fallbackFraction = double(r.fallbackPixels) / double(pixels);
  s.flooredFraction = double(r.flooredPixels) / double(pixels);
  s.skippedFraction = double(r.skippedPixels) / double(pixels);
  s.weightsFallbackFraction = double(r.weightsFallbacks.pixels) / double(pixels);
  if (reference) {
    const double e = rmse(r.image, reference->image);
    s.mse = e * e;
    s.relativeMse = relativeMse(r.image, reference->image);
    s.corrected = correctedMse(r.image, reference->image, reference->standardError);
  }
  return s;
}

}  // namespace misalloc
