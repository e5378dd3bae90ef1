#include "stats/PixelStats.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace misalloc {

double sampleVariance(double sum, double sumSquares, double count) {
  if (count < 2) return 0;
  double variance = (sumSquares - sum * sum / count) / (count - 1);
  return std::max(variance, 0.0);
}

bool isZeroVariance(double variance, double mean) {
  constexpr double kRelativeFloor = 1e-12;
  return variance <= kRelativeFloor * mean * mean;
}

PixelStats::PixelStats(int techniqueCount) : techniqueCount(techniqueCount) {
  if (techniqueCount < 1 || techniqueCount > kMaxTechniques)
    throw std::invalid_argument("PixelStats: technique count " + std::to_string(techniqueCount) + " outside [1, " +
                                std::to_string(kMaxTechniques) + "]");
}

bool PixelStats::add(int k, double f, const double* pdfs) {
  if (k < 0 || k >= techniqueCount)
    throw std::out_of_range("PixelStats::add: technique " + std::to_string(k) + " of " +
                            std::to_string(techniqueCount));
  double pdfSum = 0;
  bool valid = std::isfinite(f);
  for (int i = 0; i < techniqueCount; ++i) {
    valid = valid && std::isfinite(pdfs[i]) && pdfs[i] >= 0;
    pdfSum += pdfs[i];
  }
  valid = valid && (pdfs[k] > 0 || f == 0);
  if (!valid) {
    rejectedCount += 1;
    return false;
  }
  double w = f == 0 ? 0 : f / pdfs[k];
  double b = f == 0 ? 0 : f / pdfSum;
  TechniqueStats& t = technique[k];
  t.count += 1;
  t.sumW += w;
  t.sumW2 += w * w;
  t.sumBalance += b;
  t.sumBalance2 += b * b;
  t.sumF += f;
  for (int i = 0; i < techniqueCount; ++i) t.sumPdf[i] += pdfs[i];
  return true;
}

bool PixelStats::isFinite() const {
  for (int k = 0; k < techniqueCount; ++k) {
    const TechniqueStats& t = technique[k];
    for (double v : {t.count, t.sumW, t.sumW2, t.sumBalance, t.sumBalance2, t.sumF})
      if (!std::isfinite(v)) return false;
    for (int i = 0; i < techniqueCount; ++i)
      if (!std::isfinite(t.sumPdf[i])) return false;
  }
  return true;
}

}  // namespace misalloc
