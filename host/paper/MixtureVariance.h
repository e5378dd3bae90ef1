#pragma once
// Exact (quadrature) variances of balance-heuristic MIS on a 1D example, N = 1.

#include <vector>

#include "paper/Example1D.h"

namespace misalloc {

struct VarianceValue {
  double value;  // +∞ if Infinite, NaN if Undefined; the formal integral if SignedDensity
  VarianceStatus status;
};

// The integrals of f against the mixture p_α that the variance formulas are built from.
struct MixtureMoments {
  VarianceStatus status;
  double secondMoment;                        // λ = ∫ f²/p_α ([HS14] eq. 4.11)
  std::vector<double> techniqueSecondMoment;  // E_j = ∫ f² p_j / p_α² ([HS14] eq. 4.9)
  std::vector<double> techniqueMean;          // m_i = ∫ f p_i / p_α ([SS23] eq. 5; μ_i/α_i of [SHS16] eq. 22)
  std::vector<double> crossMoment;            // B_ij = ∫ f p_i p_j / p_α², row-major, if asked for
};

// All moments in one adaptive quadrature, after SecondMomentCheck has decided that they
// exist: +∞ for Infinite, NaN for Undefined. Throws std::runtime_error if the quadrature
// of a valid mixture does not converge.
MixtureMoments mixtureMoments(const Example1D& example, const std::vector<double>& alpha,
                              bool withCrossMoments = false);

// [SHS16] eq. 35 ([HS14] eq. 4.5): one-sample balance heuristic, λ − I².
VarianceValue oneSampleVariance(const MixtureMoments& moments, double integral);
VarianceValue oneSampleVariance(const Example1D& example, const std::vector<double>& alpha);

// [SHS16] eq. 21 (Table 2), [SS23] eq. 3: multi-sample balance heuristic with n_i = α_i N,
// λ − Σ_i μ_i²/α_i = λ − Σ_i α_i m_i²; a technique with α_i = 0 contributes 0.
VarianceValue multiSampleVariance(const MixtureMoments& moments, const std::vector<double>& alpha);
VarianceValue multiSampleVariance(const Example1D& example, const std::vector<double>& alpha);

// [HS14] eq. 4.18 ([SHS16]'s V[G_k]): the variance of technique k on its own.
VarianceValue techniqueVariance(const Example1D& example, int k);

// [SHS16] eq. 44: V[𝓕¹] − V[F¹] = Σ_i μ_i²/α_i − I², the price of choosing the technique
// at random.
double oneSampleExcess(const MixtureMoments& moments, const std::vector<double>& alpha, double integral);

// (Σ_k c_k α_k)·V: cost × variance per sample, the inverse of efficiency ([HS14] Sec. 4.2,
// [SHS16] Sec. 2.1). Relative efficiencies in the papers are ratios of it.
double inefficiency(const std::vector<double>& costs, const std::vector<double>& alpha, double variance);

// [SHS16] eq. 28: σ_i of the estimator with count-independent weights p_i/Σ_k p_k (eq. 26).
std::vector<double> countIndependentSigmas(const Example1D& example);

// [SHS16] eq. 29 for N = 1: Σ_i σ_i²/α_i. With α_i = 0 and σ_i > 0 technique i's share of
// the integral is never estimated; that is reported as +∞.
double countIndependentVariance(const std::vector<double>& sigmas, const std::vector<double>& alpha);

}  // namespace misalloc
