// Decides, before anything is integrated, whether ∫ f²/p over [a, b] is the finite
// second moment of a sampler, for a mixture p = Σ α_k p_k of given "densities".
#pragma once

#include <optional>
#include <vector>

#include "paper/Density1D.h"

namespace misalloc {

enum class VarianceStatus {
    Finite,         // p ≥ 0 and ∫ f²/p < ∞
    Infinite,       // p ≥ 0 but p → 0 where f ≠ 0 fast enough that ∫ f²/p diverges
    SignedDensity,  // p < 0 somewhere, but only where f = 0 too: the integral exists,
                    // yet it is no sampler's second moment
    Undefined,      // p changes sign where f ≠ 0: a pole inside the domain, no value
};

class SecondMomentCheck {
  public:
    SecondMomentCheck(Function1D f, std::vector<Density1D> pdfs, double a, double b);

    VarianceStatus classify(const std::vector<double>& alpha) const;

    // p_α(x_j) ≥ 0 at a probe x_j is the linear constraint Σ_k α_k p_k(x_j) ≥ 0. Returns
    // its coefficients (p_1(x_j), …, p_M(x_j)) at the probe where p_α is most negative,
    // or nullopt if p_α ≥ 0 at every probe.
    std::optional<std::vector<double>> mostViolatedProbe(const std::vector<double>& alpha) const;

  private:
    std::vector<double> mixtureAtProbes(const std::vector<double>& alpha) const;
    double rootBetween(const std::vector<double>& alpha, double x0, double x1) const;
    bool diverges(const std::vector<double>& alpha, double x0, double side) const;

    Function1D f_;
    std::vector<Density1D> pdfs_;
    double a_, b_;
    // Probe points (sorted), f and every p_k there, evaluated once.
    std::vector<double> x_, fAtX_;
    std::vector<std::vector<double>> pdfAtX_;
};

}  // namespace misalloc
