#include "alloc/LinearAllocation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace misalloc {

namespace {

// A weight this close below 0 is round-off of a solution on the simplex's boundary.
constexpr double kFeasibilityTolerance = 1e-12;

bool isActive(unsigned mask, int k) { return (mask >> k) & 1u; }

int activeCount(unsigned mask) {
  int n = 0;
  for (; mask; mask &= mask - 1) ++n;
  return n;
}

std::vector<double> unitWeight(int m, int k) {
  std::vector<double> alpha(m, 0.0);
  alpha[k] = 1;
  return alpha;
}

// Eq. 17 for a pair, eq. 14 otherwise: the closed form is what a kernel would
// evaluate, and both give the same weights.
std::optional<std::vector<double>> solveActiveSet(const PixelStats& stats, unsigned mask) {
  int m = stats.techniqueCount;
  std::vector<int> active;
  for (int k = 0; k < m; ++k)
    if (isActive(mask, k)) active.push_back(k);
  if (active.size() == 1) return unitWeight(m, active[0]);
  if (active.size() > 2) return solveLinearSystem(stats, mask);
  std::optional<double> a = linearPairWeight(stats, active[0], active[1]);
  if (!a) return std::nullopt;
  std::vector<double> alpha(m, 0.0);
  alpha[active[0]] = *a;
  alpha[active[1]] = 1 - *a;
  return alpha;
}

bool isFeasible(const std::vector<double>& alpha) {
  for (double a : alpha)
    if (a < -kFeasibilityTolerance) return false;
  return true;
}

std::vector<double> clampToSimplex(std::vector<double> alpha) {
  double sum = 0;
  for (double& a : alpha) sum += (a = std::max(a, 0.0));
  for (double& a : alpha) a /= sum;
  return alpha;
}

Allocation equalOverActiveSet(int m, unsigned mask, unsigned fallbacks) {
  Allocation result{std::vector<double>(m, 0.0), fallbacks | kFallbackSingularSystem};
  for (int k = 0; k < m; ++k)
    if (isActive(mask, k)) result.alpha[k] = 1.0 / activeCount(mask);
  return result;
}

// Techniques that can enter eq. 14: those with F_k > 0. With a signed f (F_k ≤ 0 while
// some f ≠ 0) the ratio P_ik/F_k has no meaning either, so those are left out too.
unsigned signalMask(const PixelStats& stats, unsigned* fallbacks) {
  unsigned mask = 0;
  for (int k = 0; k < stats.techniqueCount; ++k) {
    if (stats.technique[k].sumF > 0)
      mask |= 1u << k;
    else
      *fallbacks |= kFallbackSilentTechnique;
  }
  return mask;
}

// Sec. 5.1, first technique.
Allocation dropMostNegative(const PixelStats& stats, unsigned mask, unsigned fallbacks) {
  int m = stats.techniqueCount;
  for (int zeroed = 0;; ++zeroed) {
    std::optional<std::vector<double>> alpha = solveActiveSet(stats, mask);
    if (!alpha) {
      Allocation equal = equalOverActiveSet(m, mask, fallbacks);
      equal.zeroedWeights = zeroed;
      return equal;
    }
    int mostNegative = -1;
    for (int k = 0; k < m; ++k)
      if ((*alpha)[k] < -kFeasibilityTolerance && (mostNegative < 0 || (*alpha)[k] < (*alpha)[mostNegative]))
        mostNegative = k;
    if (mostNegative < 0) return Allocation{clampToSimplex(*alpha), fallbacks, zeroed};
    mask &= ~(1u << mostNegative);
  }
}

// Sec. 5.1, second technique: the subsets of the active set, largest first; among the
// feasible solutions of the largest size that has one, the smallest eq. 19 variance.
// Subsets of size 1 are always feasible, so the search ends.
Allocation minSampleVariance(const PixelSamples& samples, unsigned mask, unsigned fallbacks) {
  const PixelStats& stats = samples.stats();
  int full = activeCount(mask);
  for (int size = full - 1; size >= 1; --size) {
    std::optional<std::vector<double>> best;
    double bestVariance = std::numeric_limits<double>::infinity();
    for (unsigned subset = mask; subset; subset = (subset - 1) & mask) {
      if (activeCount(subset) != size) continue;
      std::optional<std::vector<double>> alpha = solveActiveSet(stats, subset);
      if (!alpha || !isFeasible(*alpha)) continue;
      std::vector<double> clamped = clampToSimplex(*alpha);
      double variance = mixtureSampleVariance(samples, clamped);  // [SS23] eq. 19
      if (!best || variance < bestVariance) {
        best = clamped;
        bestVariance = variance;
      }
    }
    if (best) return Allocation{*best, fallbacks, full - size};
  }
  return equalOverActiveSet(stats.techniqueCount, mask, fallbacks);  // unreachable: size-1 subsets solve
}

}  // namespace

std::optional<double> linearPairWeight(const PixelStats& stats, int i, int j) {
  // P[a][b] = P_ab = Σ_l p_a(X_bl): pdf a at the samples of technique b ([SS23] eq. 18).
  const TechniqueStats& ti = stats.technique[i];
  const TechniqueStats& tj = stats.technique[j];
  double pii = ti.sumPdf[i], pji = ti.sumPdf[j], pij = tj.sumPdf[i], pjj = tj.sumPdf[j];
  double fi = ti.sumF, fj = tj.sumF;
  double denominator = pii * fj - pji * fj - pij * fi + pjj * fi;  // [SS23] eq. 17
  double alpha = (pjj * fi - pji * fj) / denominator;
  if (denominator == 0 || !std::isfinite(alpha)) return std::nullopt;
  return alpha;
}

std::optional<std::vector<double>> solveLinearSystem(const PixelStats& stats, unsigned activeMask) {
  int m = stats.techniqueCount;
  std::vector<int> active;
  for (int k = 0; k < m; ++k)
    if (isActive(activeMask, k)) active.push_back(k);
  int n = static_cast<int>(active.size());

  // Unknowns (α_active..., 1/μ). Row r: Σ_i α_i P_ik / F_k − 1/μ = 0 for k = active[r]
  // ([SS23] eq. 14); last row: Σ_i α_i = 1.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n + 1, n + 1);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n + 1);
  for (int r = 0; r < n; ++r) {
    const TechniqueStats& tk = stats.technique[active[r]];
    for (int c = 0; c < n; ++c) a(r, c) = tk.sumPdf[active[c]] / tk.sumF;
    a(r, n) = -1;
    a(n, r) = 1;
  }
  b(n) = 1;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(a);
  if (!lu.isInvertible()) return std::nullopt;
  Eigen::VectorXd x = lu.solve(b);
  if (!x.allFinite()) return std::nullopt;

  std::vector<double> alpha(m, 0.0);
  for (int c = 0; c < n; ++c) alpha[active[c]] = x(c);
  return alpha;
}

Allocation allocateLinear(const PixelStats& stats) {
  if (auto fallback = unusableStatsFallback(stats, 1)) return *fallback;
  unsigned fallbacks = kFallbackNone;
  unsigned mask = signalMask(stats, &fallbacks);
  if (mask == 0) return equalFallback(stats.techniqueCount, fallbacks | kFallbackNoSignal);
  return dropMostNegative(stats, mask, fallbacks);
}

Allocation allocateLinear(const PixelSamples& samples, ZeroWeightRule rule) {
  const PixelStats& stats = samples.stats();
  if (rule == ZeroWeightRule::DropMostNegative) return allocateLinear(stats);
  if (auto fallback = unusableStatsFallback(stats, 1)) return *fallback;
  unsigned fallbacks = kFallbackNone;
  unsigned mask = signalMask(stats, &fallbacks);
  if (mask == 0) return equalFallback(stats.techniqueCount, fallbacks | kFallbackNoSignal);
  std::optional<std::vector<double>> alpha = solveActiveSet(stats, mask);
  if (alpha && isFeasible(*alpha)) return Allocation{clampToSimplex(*alpha), fallbacks};
  if (!alpha) fallbacks |= kFallbackSingularSystem;
  return minSampleVariance(samples, mask, fallbacks);
}

}  // namespace misalloc
