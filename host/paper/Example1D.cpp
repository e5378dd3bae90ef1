#include "paper/Example1D.h"

#include <stdexcept>
#include <utility>

#include "alloc/Allocation.h"
#include "paper/Quadrature.h"

namespace misalloc {

Example1D::Example1D(std::string id, std::string title, double a, double b, Function1D f, std::vector<Density1D> pdfs,
                     std::vector<double> costs)
    : id_(std::move(id)),
      title_(std::move(title)),
      a_(a),
      b_(b),
      f_(std::move(f)),
      pdfs_(std::move(pdfs)),
      costs_(std::move(costs)),
      integral_(integrate(f_, a, b)),
      check_(f_, pdfs_, a, b) {
  validateCosts(costs_, techniqueCount());
  for (const Density1D& p : pdfs_)
    if (p.lower() != a || p.upper() != b)
      throw std::invalid_argument("Example1D " + id_ + ": density " + p.name() + " is not defined on [a, b]");
}

double Example1D::mixturePdf(const std::vector<double>& alpha, double x) const {
  return misalloc::mixturePdf(pdfs_, alpha, x);
}

}  // namespace misalloc
