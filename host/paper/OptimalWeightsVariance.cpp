#include "paper/OptimalWeightsVariance.h"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <stdexcept>

#include "paper/Quadrature.h"

namespace misalloc {

OptimalWeightsSolution optimalWeightsVariance(const Example1D& example, const std::vector<double>& alpha) {
  const int m = example.techniqueCount();
  for (double a : alpha)
    if (!(a > 0)) throw std::invalid_argument("optimalWeightsVariance: every count must be positive");
  const VarianceStatus status = example.classify(alpha);
  if (status != VarianceStatus::Finite)
    return {{status == VarianceStatus::Infinite ? std::numeric_limits<double>::infinity()
                                                : std::numeric_limits<double>::quiet_NaN(),
             status},
            {}};
  // Components: ∫ f²/p_α, b̃_i, then Ã_ik row-major. Ã needs every x where p_α > 0,
  // f = 0 included.
  const int components = 1 + m + m * m;
  auto integrand = [&](double x, double* out) {
    std::fill(out, out + components, 0.0);
    const double p = example.mixturePdf(alpha, x);
    if (!(p > 0)) return;
    const double g = example.f(x) / p;
    out[0] = example.f(x) * g;
    for (int i = 0; i < m; ++i) {
      const double ri = example.pdf(i)(x) / p;
      out[1 + i] = g * example.pdf(i)(x);
      for (int k = 0; k < m; ++k) out[1 + m + i * m + k] = ri * example.pdf(k)(x);
    }
  };
  QuadratureResult r = integrateAdaptive(integrand, components, example.lower(), example.upper());
  if (!r.converged) throw std::runtime_error("optimalWeightsVariance: quadrature did not converge for " + example.id());
  const Eigen::Map<const Eigen::VectorXd> b(r.value.data() + 1, m);
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> A(
      r.value.data() + 1 + m, m, m);
  const Eigen::VectorXd a = A.ldlt().solve(b);  // [Kon19]: A a = b
  return {{r.value[0] - b.dot(a), status}, std::vector<double>(a.data(), a.data() + m)};
}

}  // namespace misalloc
