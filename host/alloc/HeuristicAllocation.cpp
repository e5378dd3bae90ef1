#include "alloc/HeuristicAllocation.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace misalloc {

double harmonicMean(const std::vector<double>& values) {
  double sumInverse = 0;
  for (double v : values) sumInverse += 1 / v;
  return values.size() / sumInverse;
}

namespace {

// [HS14] Sec. 4.3, V_k → 0: the zero-variance techniques take all the weight.
Allocation zeroVarianceLimit(const std::vector<double>& variances, const std::vector<double>& costs) {
  Allocation a{std::vector<double>(variances.size(), 0.0), kFallbackZeroVariance};
  double norm = 0;
  for (std::size_t k = 0; k < variances.size(); ++k)
    if (variances[k] == 0) norm += 1 / costs[k];
  for (std::size_t k = 0; k < variances.size(); ++k)
    if (variances[k] == 0) a.alpha[k] = (1 / costs[k]) / norm;
  return a;
}

}  // namespace

Allocation heuristicWeights(const std::vector<double>& variances, const std::vector<double>& costs) {
  int m = static_cast<int>(variances.size());
  validateCosts(costs, m);
  bool anyZero = false, allInfinite = true;
  for (double v : variances) {
    if (!(v >= 0)) throw std::invalid_argument("heuristicWeights: variance must be >= 0 or +inf");
    anyZero = anyZero || v == 0;
    allInfinite = allInfinite && std::isinf(v);
  }
  if (anyZero) return zeroVarianceLimit(variances, costs);
  if (allInfinite) return equalFallback(m, kFallbackInfiniteVariance);

  std::vector<double> costVariance(m);
  for (int k = 0; k < m; ++k) costVariance[k] = costs[k] * variances[k];
  double h = harmonicMean(costVariance);
  Allocation a{std::vector<double>(m)};
  for (int k = 0; k < m; ++k) a.alpha[k] = h / (m * costVariance[k]);  // [HS14] eq. 4.20
  return a;
}

Allocation allocateHeuristic(const PixelStats& stats, const std::vector<double>& costs) {
  validateCosts(costs, stats.techniqueCount);
  if (auto fallback = unusableStatsFallback(stats, 2)) return *fallback;

  std::vector<double> variances(stats.techniqueCount);
  unsigned fallbacks = kFallbackNone;
  for (int k = 0; k < stats.techniqueCount; ++k) {
    const TechniqueStats& t = stats.technique[k];
    if (isSilent(t)) {
      variances[k] = std::numeric_limits<double>::infinity();
      fallbacks |= kFallbackSilentTechnique;
      continue;
    }
    double mean = t.sumW / t.count;
    double v = sampleVariance(t.sumW, t.sumW2, t.count);  // [HS14] eq. 6.19
    variances[k] = isZeroVariance(v, mean) ? 0 : v;
  }
  Allocation a = heuristicWeights(variances, costs);
  a.fallbacks |= fallbacks;
  return a;
}

Allocation allocateHeuristic(const PixelStats& stats) {
  return allocateHeuristic(stats, std::vector<double>(stats.techniqueCount, 1.0));
}

}  // namespace misalloc
