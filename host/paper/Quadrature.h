#pragma once
// Adaptive Gauss–Kronrod quadrature (7-point Gauss, 15-point Kronrod) in double
// precision, for integrands with several components evaluated together.

#include <functional>
#include <vector>

namespace misalloc {

// Writes the components of the integrand at x into values[0 .. components).
using VectorIntegrand = std::function<void(double x, double* values)>;

struct QuadratureResult {
  std::vector<double> value;
  bool converged;
};

// Integrates every component over [a, b], starting from 16 equal panels and then
// always bisecting the panel with the largest error, until each component's total
// error estimate |K15 − G7| is below relTol × ∫|f_c|. Measuring against ∫|f_c| rather
// than |∫f_c| keeps components that integrate to 0 from stalling the refinement.
// converged is false if maxPanels are used up or a panel becomes too narrow to split.
QuadratureResult integrateAdaptive(const VectorIntegrand& f, int components, double a, double b, double relTol = 1e-12,
                                   int maxPanels = 4000);

// Scalar form; throws std::runtime_error if the quadrature does not converge.
double integrate(const std::function<double(double)>& f, double a, double b);

}  // namespace misalloc
