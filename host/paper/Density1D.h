#pragma once
// A probability density on an interval, given by its shape and normalisation.

#include <functional>
#include <string>
#include <vector>

namespace misalloc {

using Function1D = std::function<double(double)>;

class Density1D {
 public:
  // p = h / ∫_a^b h, the integral computed by adaptive quadrature.
  Density1D(std::string name, Function1D shape, double a, double b);
  // p = h / s with s given: [HS14] App. C rounds ∫(x² − x/π) to 8.764 and uses that.
  Density1D(std::string name, Function1D shape, double a, double b, double normalisation);

  double operator()(double x) const { return shape_(x) / normalisation_; }
  const Function1D& shape() const { return shape_; }
  double normalisation() const { return normalisation_; }
  double lower() const { return a_; }
  double upper() const { return b_; }
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  Function1D shape_;
  double a_, b_, normalisation_;
};

// [HS14] eq. 4.3: the mixture p_α(x) = Σ_k α_k p_k(x), the density of balance-heuristic MIS.
double mixturePdf(const std::vector<Density1D>& pdfs, const std::vector<double>& alpha, double x);

// φ_{m,σ}(x), the normal density, as 003 writes its integrands.
double normalPdf(double x, double mean, double sigma);

// φ_{m,σ} truncated to [a, b] and renormalised there, as [SS23]'s Gaussian pdfs have to be
// to sample its bounded domains.
Density1D truncatedGaussian(double mean, double sigma, double a, double b);

}  // namespace misalloc
