#pragma once
// A one-dimensional MIS problem from the papers: the integrand f on [a, b], the
// techniques' densities p_k and their sampling costs c_k.

#include <string>
#include <vector>

#include "paper/Density1D.h"
#include "paper/SecondMomentCheck.h"

namespace misalloc {

class Example1D {
 public:
  // Throws std::invalid_argument if the costs are invalid (see validateCosts) or a
  // density's interval is not [a, b].
  Example1D(std::string id, std::string title, double a, double b, Function1D f, std::vector<Density1D> pdfs,
            std::vector<double> costs);

  const std::string& id() const { return id_; }
  const std::string& title() const { return title_; }
  double lower() const { return a_; }
  double upper() const { return b_; }
  double f(double x) const { return f_(x); }
  int techniqueCount() const { return static_cast<int>(pdfs_.size()); }
  const Density1D& pdf(int k) const { return pdfs_[k]; }
  const std::vector<double>& costs() const { return costs_; }
  // I = ∫_a^b f.
  double integral() const { return integral_; }

  // [HS14] eq. 4.3: p_α(x) = Σ_k α_k p_k(x).
  double mixturePdf(const std::vector<double>& alpha, double x) const;
  VarianceStatus classify(const std::vector<double>& alpha) const { return check_.classify(alpha); }
  std::optional<std::vector<double>> mostViolatedProbe(const std::vector<double>& alpha) const {
    return check_.mostViolatedProbe(alpha);
  }

 private:
  std::string id_, title_;
  double a_, b_;
  Function1D f_;
  std::vector<Density1D> pdfs_;
  std::vector<double> costs_;
  double integral_;
  SecondMomentCheck check_;
};

}  // namespace misalloc
