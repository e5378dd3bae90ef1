#include "paper/Density1D.h"

#include <fmt/format.h>

#include <cmath>
#include <utility>

#include "paper/Quadrature.h"

namespace misalloc {

Density1D::Density1D(std::string name, Function1D shape, double a, double b)
    : Density1D(std::move(name), shape, a, b, integrate(shape, a, b)) {}

Density1D::Density1D(std::string name, Function1D shape, double a, double b, double normalisation)
    : name_(std::move(name)), shape_(std::move(shape)), a_(a), b_(b), normalisation_(normalisation) {}

double mixturePdf(const std::vector<Density1D>& pdfs, const std::vector<double>& alpha, double x) {
  double p = 0;
  for (std::size_t k = 0; k < pdfs.size(); ++k) p += alpha[k] * pdfs[k](x);
  return p;
}

double normalPdf(double x, double mean, double sigma) {
  constexpr double kSqrtTwoPi = 2.50662827463100050242;
  double z = (x - mean) / sigma;
  return std::exp(-0.5 * z * z) / (sigma * kSqrtTwoPi);
}

Density1D truncatedGaussian(double mean, double sigma, double a, double b) {
  return Density1D(
      fmt::format("phi({:g},{:g})", mean, sigma), [mean, sigma](double x) { return normalPdf(x, mean, sigma); }, a, b);
}

}  // namespace misalloc
