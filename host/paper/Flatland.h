#pragma once
// [Kar19] Sec. 6.3: the flatland test of MIS compensation. A 1D HDR map on the circle
// lights a point whose normal is at angle 0; the HDR-map technique, with one of the
// pdfs below, is combined with BRDF sampling by the balance heuristic, c = 0.5 each,
// and the normalised variances (N = 1) are exact sums over the map's bins.
//
// The paper does not give its map. Map A of verified_values.json stands in: 256 bins on
// [−π, π) of a sky |t| < π/2, (0.6 + 0.4 cos t) exp(0.8 (0.6 sin(3t + 0.4) + 0.3 sin(7t
// + 1.3) + 0.2 sin(13t + 2.1))), with an occluder of radiance 0.01 on 0.95 < t < 1.35,
// a ground 0.15 (1 + 0.5 sin 5t) and a Gaussian sun at t = −0.7, σ = 0.02, of power
// 0.5; each bin holds the average over it.
#include <vector>

#include "distributions/CompensatedPdf.h"

namespace misalloc {

enum class FlatlandBrdf {
  Diffuse,  // p_ρ ∝ cos⁺ t
  Sharp,    // p_ρ ∝ cos⁺(t − π/8)²⁰ cos⁺ t: a Phong lobe tilted π/8 off the normal
};

// The HDR-map technique's pdf.
enum class FlatlandPdf {
  Original,     // ∝ L
  PracticalNi,  // [Kar19] eq. 14, ∝ max(0, L − 2(1−c) L̄)
  PracticalNd,  // [Kar19] eq. 13 with a diffuse BRDF
  Compensated,  // [Kar19] eq. 6 for the actual integrand
  Optimal,      // [Kar19] eq. 9, λ by bisection within eq. 10
};

struct FlatlandVariance {
  double oneSample = 0;    // NMSE Var/F² of one-sample MIS, N = 1
  double multiSample = 0;  // of multi-sample MIS with one sample of each technique per unit
};

class FlatlandStudy {
 public:
  explicit FlatlandStudy(FlatlandBrdf brdf, double envmapFraction = 0.5);

  // F = ∫ L p_ρ dt: the BRDF-cosine product is normalised, as in the stand-in.
  double integral() const { return integral_; }
  FlatlandVariance variance(FlatlandPdf pdf) const;
  // One technique alone, one-sample NMSE: the original HDR-map pdf, or the BRDF's.
  double hdrOnly() const;
  double brdfOnly() const;
  const OptimalLambda& lambda() const { return lambda_; }
  // ∫ (p_compensated − p_optimal)² / ∫ p_optimal²: how far eq. 6 is from eq. 9.
  double compensatedVsOptimal() const;

 private:
  // The HDR-map pdf at the quadrature nodes.
  std::vector<double> pdfAtNodes(FlatlandPdf pdf) const;
  // Var/F² with technique weights c (HDR map) and 1 − c (BRDF).
  FlatlandVariance varianceOf(const std::vector<double>& hdrPdf, double c) const;

  double c_;
  std::vector<double> t_, weight_, radiance_, brdfPdf_;  // per node: angle, quadrature weight, L of its bin, p_ρ
  std::vector<double> bins_;                             // the map's bin averages
  double integral_ = 0;
  OptimalLambda lambda_;
};

// Map A's 256 bin averages, bin b covering [−π + 2πb/256, −π + 2π(b+1)/256).
std::vector<double> flatlandMapA();

}  // namespace misalloc
