#include "paper/InverseCdfSampler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace misalloc {

namespace {

constexpr int kCells = 512;

// 8-point Gauss–Legendre on [-1, 1] (x ≥ 0 half). A cell spans 1/512 of the domain,
// where the examples' shapes are smooth enough for it to be exact in double.
constexpr double kNodes[4] = {0.183434642495649804939476142360184, 0.525532409916328985817739049189254,
                              0.796666477413626739591553936475830, 0.960289856497536231683560868569473};
constexpr double kWeights[4] = {0.362683783378361982965150449277196, 0.313706645877887287337962201986601,
                                0.222381034453374470544355994426241, 0.101228536290376259152531354309962};

double gaussLegendre(const Function1D& h, double x0, double x1) {
  double center = 0.5 * (x0 + x1), halfWidth = 0.5 * (x1 - x0), sum = 0;
  for (int i = 0; i < 4; ++i)
    sum += kWeights[i] * (h(center - halfWidth * kNodes[i]) + h(center + halfWidth * kNodes[i]));
  return sum * halfWidth;
}

}  // namespace

InverseCdfSampler::InverseCdfSampler(const Density1D& density)
    : shape_(density.shape()), a_(density.lower()), width_((density.upper() - density.lower()) / kCells) {
  cumulative_.push_back(0);
  for (int c = 0; c < kCells; ++c) {
    double x0 = a_ + c * width_;
    for (double x : {x0, x0 + 0.5 * width_, x0 + width_})
      if (shape_(x) < 0)
        throw std::domain_error("density " + density.name() + " is negative at x = " + std::to_string(x) +
                                ": it cannot be sampled");
    cumulative_.push_back(cumulative_.back() + cellIntegral(c, x0 + width_));
  }
}

double InverseCdfSampler::cellIntegral(int cell, double x) const {
  return gaussLegendre(shape_, a_ + cell * width_, x);
}

double InverseCdfSampler::sample(double u) const {
  double target = u * cumulative_.back();
  int cell =
      static_cast<int>(std::upper_bound(cumulative_.begin(), cumulative_.end(), target) - cumulative_.begin()) - 1;
  cell = std::clamp(cell, 0, kCells - 1);
  double lo = a_ + cell * width_, hi = lo + width_;
  double residual = target - cumulative_[cell], mass = cumulative_[cell + 1] - cumulative_[cell];
  double x = mass > 0 ? lo + width_ * std::clamp(residual / mass, 0.0, 1.0) : lo;
  // Newton on G(x) = ∫_lo^x h − residual, falling back to bisection whenever a step
  // would leave the bracket [lo, hi] that G's monotonicity maintains.
  for (int i = 0; i < 50; ++i) {
    double g = cellIntegral(cell, x) - residual;
    if (g > 0)
      hi = x;
    else
      lo = x;
    double h = shape_(x);
    double next = h > 0 ? x - g / h : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - x) <= 1e-15 * width_) return next;
    x = next;
  }
  return x;
}

}  // namespace misalloc
