#include "alloc/SigmaAllocation.h"

#include <cmath>
#include <stdexcept>

namespace misalloc {

Allocation sigmaSqrtCWeights(const std::vector<double>& sigmas, const std::vector<double>& costs) {
  int m = static_cast<int>(sigmas.size());
  validateCosts(costs, m);
  std::vector<double> share(m);
  double total = 0;
  for (int i = 0; i < m; ++i) {
    if (!(std::isfinite(sigmas[i]) && sigmas[i] >= 0))
      throw std::invalid_argument("sigmaSqrtCWeights: sigma must be finite and >= 0");
    share[i] = sigmas[i] / std::sqrt(costs[i]);  // [SHS16] eq. 31
    total += share[i];
  }
  if (total == 0) return equalFallback(m, kFallbackZeroVariance);
  Allocation a{std::vector<double>(m)};
  for (int i = 0; i < m; ++i) a.alpha[i] = share[i] / total;
  return a;
}

Allocation allocateSigmaSqrtC(const PixelStats& stats, const std::vector<double>& costs) {
  validateCosts(costs, stats.techniqueCount);
  if (auto fallback = unusableStatsFallback(stats, 2)) return *fallback;

  std::vector<double> sigmas(stats.techniqueCount);
  unsigned fallbacks = kFallbackNone;
  for (int i = 0; i < stats.techniqueCount; ++i) {
    const TechniqueStats& t = stats.technique[i];
    if (isSilent(t)) fallbacks |= kFallbackSilentTechnique;
    double mean = t.sumBalance / t.count;
    double v = sampleVariance(t.sumBalance, t.sumBalance2, t.count);  // [HS14] eq. 6.19
    sigmas[i] = isZeroVariance(v, mean) ? 0 : std::sqrt(v);
  }
  Allocation a = sigmaSqrtCWeights(sigmas, costs);
  a.fallbacks |= fallbacks;
  return a;
}

Allocation allocateSigmaSqrtC(const PixelStats& stats) {
  return allocateSigmaSqrtC(stats, std::vector<double>(stats.techniqueCount, 1.0));
}

}  // namespace misalloc
