#pragma once
// Inverse-CDF sampling of a 1D density: a tabulated CDF locates the cell, Newton's
// method on the exact cell integral finds the point, so samples follow the density
// itself rather than a piecewise approximation of it.

#include <vector>

#include "paper/Density1D.h"

namespace misalloc {

class InverseCdfSampler {
 public:
  // Throws std::domain_error if the shape is negative anywhere it is probed: such a
  // "density" cannot be sampled ([HS14] App. C's x² − x/π on [0, 1/π]).
  explicit InverseCdfSampler(const Density1D& density);

  // The point x with CDF(x) = u, for u in [0, 1).
  double sample(double u) const;

 private:
  double cellIntegral(int cell, double x) const;

  Function1D shape_;
  double a_, width_;
  std::vector<double> cumulative_;  // ∫ shape from a to the start of each cell, and the total
};

}  // namespace misalloc
