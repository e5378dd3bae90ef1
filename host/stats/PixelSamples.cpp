#include "stats/PixelSamples.h"

#include <limits>

namespace misalloc {

PixelSamples::PixelSamples(int techniqueCount) : stats_(techniqueCount) {}

bool PixelSamples::add(int k, double f, const double* pdfs) {
  if (!stats_.add(k, f, pdfs)) return false;
  StoredSample s{f, {}};
  for (int i = 0; i < techniqueCount(); ++i) s.pdf[i] = pdfs[i];
  samples_[k].push_back(s);
  return true;
}

double mixtureSampleVariance(const PixelSamples& samples, const std::vector<double>& alpha) {
  double variance = 0;
  for (int i = 0; i < samples.techniqueCount(); ++i) {
    const std::vector<StoredSample>& technique = samples.samples(i);
    if (alpha[i] == 0 || technique.empty()) continue;
    double sum = 0, sumSquares = 0;
    for (const StoredSample& s : technique) {
      if (s.f == 0) continue;
      double p = 0;
      for (int k = 0; k < samples.techniqueCount(); ++k) p += alpha[k] * s.pdf[k];
      if (p == 0) return std::numeric_limits<double>::infinity();
      sum += s.f / p;
      sumSquares += (s.f / p) * (s.f / p);
    }
    double n = static_cast<double>(technique.size());
    double mean = sum / n;
    variance += alpha[i] * (sumSquares / n - mean * mean);
  }
  return variance;
}

}  // namespace misalloc
