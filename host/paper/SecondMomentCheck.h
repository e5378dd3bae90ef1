#pragma once
// Decides, before anything is integrated, whether ∫ f²/p over [a, b] is the finite
// second moment of a sampler, for a mixture p = Σ α_k p_k of given "densities".
// Zeros of p are looked for at the ends of [a, b] and at sign changes between probes;
// a zero that p touches without changing sign strictly inside the domain is not seen.
// None of the papers' examples has one: their pdfs vanish inside only where f does.

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

  // p_α(x_j) ≥ 0 at a probe x_j is the linear constraint a·α ≥ 0 with
  // a ∝ (p_1(x_j), …, p_M(x_j)). Returns the unit normal a of the violated constraint
  // α lies farthest outside of, or nullopt if p_α ≥ 0 at every probe. Near an endpoint
  // where the p_k vanish, that picks the probe closest to it, whose constraint is the
  // limit of its neighbours'.
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
