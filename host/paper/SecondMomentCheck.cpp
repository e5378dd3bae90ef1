#include "paper/SecondMomentCheck.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace misalloc {

namespace {

// Probes: a uniform grid plus points 2^-j (b − a) from either end, so that the sign
// of a mixture is seen in the thin boundary layers where [HS14] App. C's mixtures first
// turn negative.
constexpr int kGridCells = 1024;
constexpr int kBoundaryLevels = 40;

}  // namespace

SecondMomentCheck::SecondMomentCheck(Function1D f, std::vector<Density1D> pdfs, double a, double b)
    : f_(std::move(f)), pdfs_(std::move(pdfs)), a_(a), b_(b) {
  for (int i = 0; i <= kGridCells; ++i) x_.push_back(i == kGridCells ? b : a + (b - a) * i / kGridCells);
  for (int j = 1; j <= kBoundaryLevels; ++j) {
    x_.push_back(a + std::ldexp(b - a, -j));
    x_.push_back(b - std::ldexp(b - a, -j));
  }
  std::sort(x_.begin(), x_.end());
  x_.erase(std::unique(x_.begin(), x_.end()), x_.end());
  for (double x : x_) fAtX_.push_back(f_(x));
  pdfAtX_.resize(pdfs_.size());
  for (std::size_t k = 0; k < pdfs_.size(); ++k)
    for (double x : x_) pdfAtX_[k].push_back(pdfs_[k](x));
}

double SecondMomentCheck::rootBetween(const std::vector<double>& alpha, double x0, double x1) const {
  double p0 = mixturePdf(pdfs_, alpha, x0);
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (x0 + x1);
    if (!(x0 < mid && mid < x1)) break;
    double pm = mixturePdf(pdfs_, alpha, mid);
    if (pm == 0) return mid;
    if ((pm < 0) == (p0 < 0)) {
      x0 = mid;
      p0 = pm;
    } else {
      x1 = mid;
    }
  }
  return 0.5 * (x0 + x1);
}

// For analytic f and p, f²/|p| ~ C |x − x0|^β near x0 with an integer β, and the
// integral converges iff β ≥ 0, i.e. iff d · f²/|p| → 0 at distance d. Comparing that
// product 2^8 times closer separates β ≥ 0 (it shrinks by ≥ 2^8) from β ≤ −1 (it does
// not shrink).
bool SecondMomentCheck::diverges(const std::vector<double>& alpha, double x0, double side) const {
  auto weighted = [&](double d) {
    double x = x0 + side * d, fx = f_(x);
    return fx == 0 ? 0.0 : d * fx * fx / std::abs(mixturePdf(pdfs_, alpha, x));
  };
  double far = weighted(std::ldexp(b_ - a_, -20)), near = weighted(std::ldexp(b_ - a_, -28));
  return near > 0 && near > 0.5 * far;
}

std::vector<double> SecondMomentCheck::mixtureAtProbes(const std::vector<double>& alpha) const {
  std::vector<double> p(x_.size(), 0.0);
  for (std::size_t k = 0; k < pdfs_.size(); ++k)
    for (std::size_t i = 0; i < x_.size(); ++i) p[i] += alpha[k] * pdfAtX_[k][i];
  return p;
}

std::optional<std::vector<double>> SecondMomentCheck::mostViolatedProbe(const std::vector<double>& alpha) const {
  std::vector<double> p = mixtureAtProbes(alpha);
  std::optional<std::vector<double>> worst;
  double worstDistance = 0;
  for (std::size_t i = 0; i < x_.size(); ++i) {
    if (!(p[i] < 0)) continue;
    std::vector<double> row;
    double norm = 0;
    for (const std::vector<double>& pdf : pdfAtX_) {
      row.push_back(pdf[i]);
      norm += pdf[i] * pdf[i];
    }
    double distance = -p[i] / std::sqrt(norm);
    if (distance <= worstDistance) continue;
    for (double& a : row) a /= std::sqrt(norm);
    worst = row;
    worstDistance = distance;
  }
  return worst;
}

VarianceStatus SecondMomentCheck::classify(const std::vector<double>& alpha) const {
  std::size_t n = x_.size();
  std::vector<double> p = mixtureAtProbes(alpha);

  bool anyNegative = std::any_of(p.begin(), p.end(), [](double v) { return v < 0; });
  bool anyPositive = std::any_of(p.begin(), p.end(), [](double v) { return v > 0; });
  if (!anyPositive) return VarianceStatus::Undefined;
  if (anyNegative) {
    // Every sign change must be a zero of f as well, or 1/p has a pole there.
    std::size_t last = n;  // the last probe with p ≠ 0
    for (std::size_t i = 0; i < n; ++i) {
      if (p[i] == 0) continue;
      if (last < n && (p[last] < 0) != (p[i] < 0)) {
        double root = rootBetween(alpha, x_[last], x_[i]);
        if (diverges(alpha, root, -1) || diverges(alpha, root, +1)) return VarianceStatus::Undefined;
      }
      last = i;
    }
    return VarianceStatus::SignedDensity;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (p[i] == 0 && fAtX_[i] != 0) return VarianceStatus::Infinite;
  if (diverges(alpha, a_, +1) || diverges(alpha, b_, -1)) return VarianceStatus::Infinite;
  return VarianceStatus::Finite;
}

}  // namespace misalloc
