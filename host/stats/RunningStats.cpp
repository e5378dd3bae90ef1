#include "stats/RunningStats.h"

#include "KernelCode.h"

namespace misalloc {

PixelStats decodePixelStats(const double* slots, unsigned mask, int techniqueCount) {
  PixelStats stats(techniqueCount);
  const int perTechnique = MA_STATS_PER_TECHNIQUE(int(mask), techniqueCount);
  for (int k = 0; k < techniqueCount; ++k) {
    const double* s = slots + k * perTechnique;
    TechniqueStats& t = stats.technique[k];
    t.count = *s++;
    if (mask & MA_STATS_TECHNIQUE) {
      t.sumW = *s++;
      t.sumW2 = *s++;
    }
    if (mask & MA_STATS_BALANCE) {
      t.sumBalance = *s++;
      t.sumBalance2 = *s++;
    }
    if (mask & MA_STATS_LINEAR) {
      t.sumF = *s++;
      for (int i = 0; i < techniqueCount; ++i) t.sumPdf[i] = *s++;
    }
  }
  return stats;
}

PixelSamples decodePixelSamples(const std::vector<float>& stored, int pixel, int taken, int capacity,
                                int techniqueCount) {
  PixelSamples samples(techniqueCount);
  double pdfs[kMaxTechniques] = {};
  for (int i = 0; i < taken; ++i) {
    auto at = [&](int q) { return stored[kern::storedSampleIndex(pixel, i, q, capacity, techniqueCount)]; };
    for (int l = 0; l < techniqueCount; ++l) pdfs[l] = at(2 + l);
    samples.add(int(at(0)), at(1), pdfs);
  }
  return samples;
}

}  // namespace misalloc
