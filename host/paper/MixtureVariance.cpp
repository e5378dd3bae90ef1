#include "paper/MixtureVariance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "paper/Quadrature.h"

namespace misalloc {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

MixtureMoments filledMoments(VarianceStatus status, int m, double value, bool withCrossMoments) {
  return MixtureMoments{status, value, std::vector<double>(m, value), std::vector<double>(m, value),
                        std::vector<double>(withCrossMoments ? m * m : 0, value)};
}

// Σ_i μ_i²/α_i = Σ_i α_i m_i², the term [SHS16] eq. 21 subtracts; 0 for α_i = 0.
double weightedMeanSquares(const MixtureMoments& moments, const std::vector<double>& alpha) {
  double sum = 0;
  for (std::size_t i = 0; i < alpha.size(); ++i)
    if (alpha[i] != 0) sum += alpha[i] * moments.techniqueMean[i] * moments.techniqueMean[i];
  return sum;
}

VarianceValue varianceFrom(const MixtureMoments& moments, double value) {
  if (moments.status == VarianceStatus::Infinite) return {kInfinity, moments.status};
  if (moments.status == VarianceStatus::Undefined) return {kNaN, moments.status};
  return {value, moments.status};
}

}  // namespace

MixtureMoments mixtureMoments(const Example1D& example, const std::vector<double>& alpha, bool withCrossMoments) {
  int m = example.techniqueCount();
  VarianceStatus status = example.classify(alpha);
  if (status == VarianceStatus::Infinite) return filledMoments(status, m, kInfinity, withCrossMoments);
  if (status == VarianceStatus::Undefined) return filledMoments(status, m, kNaN, withCrossMoments);

  // Components: λ, E_1..E_M, m_1..m_M, then B_ij.
  int components = 1 + 2 * m + (withCrossMoments ? m * m : 0);
  auto integrand = [&](double x, double* out) {
    double fx = example.f(x);
    std::fill(out, out + components, 0.0);
    if (fx == 0) return;
    double p = example.mixturePdf(alpha, x);
    double g = fx / p;
    out[0] = fx * g;
    for (int i = 0; i < m; ++i) {
      double pi = example.pdf(i)(x);
      out[1 + i] = g * g * pi;
      out[1 + m + i] = g * pi;
      if (!withCrossMoments) continue;
      for (int j = 0; j < m; ++j) out[1 + 2 * m + i * m + j] = g / p * pi * example.pdf(j)(x);
    }
  };
  QuadratureResult r = integrateAdaptive(integrand, components, example.lower(), example.upper());
  if (!r.converged) {
    // A sign-changing "density" may leave an integrand quadrature cannot resolve;
    // a valid mixture never should.
    if (status == VarianceStatus::SignedDensity)
      return filledMoments(VarianceStatus::Undefined, m, kNaN, withCrossMoments);
    throw std::runtime_error("mixtureMoments: quadrature did not converge for example " + example.id());
  }
  MixtureMoments moments{status, r.value[0], {}, {}, {}};
  moments.techniqueSecondMoment.assign(r.value.begin() + 1, r.value.begin() + 1 + m);
  moments.techniqueMean.assign(r.value.begin() + 1 + m, r.value.begin() + 1 + 2 * m);
  moments.crossMoment.assign(r.value.begin() + 1 + 2 * m, r.value.end());
  return moments;
}

VarianceValue oneSampleVariance(const MixtureMoments& moments, double integral) {
  return varianceFrom(moments, moments.secondMoment - integral * integral);
}

VarianceValue oneSampleVariance(const Example1D& example, const std::vector<double>& alpha) {
  return oneSampleVariance(mixtureMoments(example, alpha), example.integral());
}

VarianceValue multiSampleVariance(const MixtureMoments& moments, const std::vector<double>& alpha) {
  return varianceFrom(moments, moments.secondMoment - weightedMeanSquares(moments, alpha));
}

VarianceValue multiSampleVariance(const Example1D& example, const std::vector<double>& alpha) {
  return multiSampleVariance(mixtureMoments(example, alpha), alpha);
}

VarianceValue techniqueVariance(const Example1D& example, int k) {
  std::vector<double> alpha(example.techniqueCount(), 0.0);
  alpha[k] = 1;
  return oneSampleVariance(example, alpha);
}

double oneSampleExcess(const MixtureMoments& moments, const std::vector<double>& alpha, double integral) {
  return weightedMeanSquares(moments, alpha) - integral * integral;
}

double inefficiency(const std::vector<double>& costs, const std::vector<double>& alpha, double variance) {
  double cost = 0;
  for (std::size_t k = 0; k < costs.size(); ++k) cost += costs[k] * alpha[k];
  return cost * variance;
}

std::vector<double> countIndependentSigmas(const Example1D& example) {
  // With α = 1/M the mixture is Σ_k p_k / M, so E_i = M² ∫ p_i f²/(Σ p_k)² and
  // m_i = M μ_i, the two integrals of eq. 28.
  int m = example.techniqueCount();
  std::vector<double> equal(m, 1.0 / m);
  MixtureMoments moments = mixtureMoments(example, equal);
  std::vector<double> sigmas(m);
  for (int i = 0; i < m; ++i) {
    double mu = moments.techniqueMean[i] / m;
    sigmas[i] = std::sqrt(std::max(0.0, moments.techniqueSecondMoment[i] / (m * m) - mu * mu));
  }
  return sigmas;
}

double countIndependentVariance(const std::vector<double>& sigmas, const std::vector<double>& alpha) {
  double v = 0;
  for (std::size_t i = 0; i < sigmas.size(); ++i) {
    if (sigmas[i] == 0) continue;
    if (alpha[i] == 0) return kInfinity;
    v += sigmas[i] * sigmas[i] / alpha[i];
  }
  return v;
}

}  // namespace misalloc
