#include "paper/Flatland.h"

#include <cmath>
#include <stdexcept>

#include "Constants.h"
#include "distributions/CompensatedPdf.h"
#include "paper/Quadrature.h"

namespace misalloc {
namespace {

constexpr int kBins = 256;
constexpr double kBinWidth = 2 * kPi / kBins;
constexpr int kNodesPerBin = 20;

// Gauss–Legendre nodes and weights on [−1, 1], by Newton's method on P_n.
void gaussLegendre(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  for (int i = 1; i <= n; ++i) {
    double x = std::cos(kPi * (i - 0.25) / (n + 0.5)), derivative = 0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= n; ++k) {
        double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      derivative = n * (x * p1 - p0) / (x * x - 1);
      double step = p1 / derivative;
      x -= step;
      if (std::abs(step) < 1e-15) break;
    }
    nodes.push_back(x);
    weights.push_back(2 / ((1 - x * x) * derivative * derivative));
  }
}

// Map A without its sun.
double skyAndGround(double t) {
  if (std::abs(t) >= kPi / 2) return 0.15 * (1 + 0.5 * std::sin(5 * t));
  if (t > 0.95 && t < 1.35) return 0.01;
  return (0.6 + 0.4 * std::cos(t)) *
         std::exp(0.8 * (0.6 * std::sin(3 * t + 0.4) + 0.3 * std::sin(7 * t + 1.3) + 0.2 * std::sin(13 * t + 2.1)));
}

double normalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

double cosPlus(double t) { return std::max(0.0, std::cos(t)); }

// Up to normalisation. Its kinks at ±π/2 and at π/8 ± π/2 fall on bin edges (multiples
// of π/128 from −π), so Gauss–Legendre per bin integrates it to double precision.
double brdfShape(FlatlandBrdf brdf, double t) {
  return brdf == FlatlandBrdf::Diffuse ? cosPlus(t) : std::pow(cosPlus(t - kPi / 8), 20) * cosPlus(t);
}

}  // namespace

std::vector<double> flatlandMapA() {
  std::vector<double> bins(kBins);
  for (int b = 0; b < kBins; ++b) {
    const double lo = -kPi + b * kBinWidth, hi = lo + kBinWidth;
    std::vector<double> cuts{lo};
    for (double edge : {-kPi / 2, 0.95, 1.35, kPi / 2})
      if (edge > lo && edge < hi) cuts.push_back(edge);
    cuts.push_back(hi);
    double sum = 0;
    for (size_t i = 0; i + 1 < cuts.size(); ++i) sum += integrate(skyAndGround, cuts[i], cuts[i + 1]);
    sum += 0.5 * (normalCdf((hi + 0.7) / 0.02) - normalCdf((lo + 0.7) / 0.02));  // the sun's share of the bin
    bins[b] = sum / kBinWidth;
  }
  return bins;
}

FlatlandStudy::FlatlandStudy(FlatlandBrdf brdf, double envmapFraction) : c_(envmapFraction), bins_(flatlandMapA()) {
  std::vector<double> x, w;
  gaussLegendre(kNodesPerBin, x, w);
  double brdfTotal = 0;
  for (int b = 0; b < kBins; ++b)
    for (int i = 0; i < kNodesPerBin; ++i) {
      const double t = -kPi + (b + 0.5 * (1 + x[i])) * kBinWidth;
      t_.push_back(t);
      weight_.push_back(0.5 * kBinWidth * w[i]);
      radiance_.push_back(bins_[b]);
      brdfPdf_.push_back(brdfShape(brdf, t));
      brdfTotal += weight_.back() * brdfPdf_.back();
    }
  for (size_t n = 0; n < t_.size(); ++n) {
    brdfPdf_[n] /= brdfTotal;
    integral_ += weight_[n] * radiance_[n] * brdfPdf_[n];
  }

  std::vector<double> f(t_.size()), q(t_.size());
  for (size_t n = 0; n < t_.size(); ++n) {
    f[n] = radiance_[n] * brdfPdf_[n];
    q[n] = (1 - c_) * brdfPdf_[n];
  }
  lambda_ = solveOptimalLambda(f.data(), q.data(), weight_.data(), t_.size(), integral_, c_);
}

std::vector<double> FlatlandStudy::pdfAtNodes(FlatlandPdf pdf) const {
  std::vector<double> p(t_.size());
  double meanRadiance = 0;
  for (double L : bins_) meanRadiance += L / kBins;
  // Practical-nd assumes a diffuse BRDF: p_ρ ∝ cos⁺, and F of that product.
  std::vector<double> diffuse(t_.size());
  double diffuseIntegral = 0;
  for (size_t n = 0; n < t_.size(); ++n) {
    diffuse[n] = cosPlus(t_[n]) / 2;
    diffuseIntegral += weight_[n] * radiance_[n] * diffuse[n];
  }
  for (size_t n = 0; n < t_.size(); ++n) {
    const double f = radiance_[n] * brdfPdf_[n], q = (1 - c_) * brdfPdf_[n];
    switch (pdf) {
      case FlatlandPdf::Original:
        p[n] = radiance_[n];
        break;
      case FlatlandPdf::PracticalNi:
        p[n] = compensatedLuminance(radiance_[n], meanRadiance, c_);
        break;
      case FlatlandPdf::PracticalNd:
        p[n] = misCompensated(radiance_[n] * diffuse[n], (1 - c_) * diffuse[n], diffuseIntegral, c_);
        break;
      case FlatlandPdf::Compensated:
        p[n] = misCompensated(f, q, integral_, c_);
        break;
      case FlatlandPdf::Optimal:
        p[n] = optimalFree(f, q, lambda_.lambda, c_);
        break;
    }
  }
  double total = 0;
  for (size_t n = 0; n < t_.size(); ++n) total += weight_[n] * p[n];
  if (!(total > 0)) throw std::logic_error("flatland: an HDR-map pdf with no mass");
  for (double& v : p) v /= total;
  return p;
}

// One-sample: ∫ f²/p_eff − F² with p_eff = c p_I + (1−c) p_ρ ([Kar19] eq. 4). Multi-sample
// with fixed counts c, 1−c: ∫ f²/p_eff − Σ_i μ_i²/c_i, μ_i = ∫ c_i p_i f / p_eff ([SHS16] Table 2).
FlatlandVariance FlatlandStudy::varianceOf(const std::vector<double>& hdrPdf, double c) const {
  double second = 0, muHdr = 0, muBrdf = 0;
  for (size_t n = 0; n < t_.size(); ++n) {
    const double f = radiance_[n] * brdfPdf_[n];
    if (f == 0) continue;
    const double effective = c * hdrPdf[n] + (1 - c) * brdfPdf_[n];
    second += weight_[n] * f * f / effective;
    muHdr += weight_[n] * c * hdrPdf[n] * f / effective;
    muBrdf += weight_[n] * (1 - c) * brdfPdf_[n] * f / effective;
  }
  const double F2 = integral_ * integral_;
  FlatlandVariance v;
  v.oneSample = second / F2 - 1;
  v.multiSample = c > 0 && c < 1 ? (second - muHdr * muHdr / c - muBrdf * muBrdf / (1 - c)) / F2 : v.oneSample;
  return v;
}

FlatlandVariance FlatlandStudy::variance(FlatlandPdf pdf) const { return varianceOf(pdfAtNodes(pdf), c_); }

double FlatlandStudy::hdrOnly() const { return varianceOf(pdfAtNodes(FlatlandPdf::Original), 1).oneSample; }

double FlatlandStudy::brdfOnly() const { return varianceOf(pdfAtNodes(FlatlandPdf::Original), 0).oneSample; }

double FlatlandStudy::compensatedVsOptimal() const {
  std::vector<double> compensated = pdfAtNodes(FlatlandPdf::Compensated), optimal = pdfAtNodes(FlatlandPdf::Optimal);
  double difference = 0, norm = 0;
  for (size_t n = 0; n < t_.size(); ++n) {
    difference += weight_[n] * (compensated[n] - optimal[n]) * (compensated[n] - optimal[n]);
    norm += weight_[n] * optimal[n] * optimal[n];
  }
  return difference / norm;
}

}  // namespace misalloc
