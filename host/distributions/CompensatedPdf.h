#pragma once
// MIS compensation [Kar19]: when envmap sampling is combined with BRDF sampling by
// MIS, the envmap pdf should cover what BRDF sampling leaves uncovered, not the whole
// radiance. The practical, normal-independent form ([Kar19] eq. 14) subtracts a
// constant from the luminance before tabulating it. The general forms (eqs. 5–10) are
// here too: host/distributions/OptimalBank.h tabulates them per BRDF, host/paper/Flatland.h
// reproduces the paper's 1D test with them.
#include <cstddef>
#include <string>
#include <vector>

namespace misalloc {

// The optimal pdf per pixel's cells across the map by default: 32 × 16 cells of 11.25°,
// which beat 16 × 8 at equal time on real geometry (docs/results.md, "Finer cells for
// the optimal pdf per pixel"); and the range a spec may ask for.
constexpr int kDefaultPixelCellsAcross = 32;
constexpr int kMinPixelCellsAcross = 4, kMaxPixelCellsAcross = 64;
// The pilot's cells across at most (EnvmapPdf::pilotCellsAcross): a stage that keeps
// statistics builds a table of 16 × 8 cells, a quarter of the default's build, since
// its samples weigh little in the image and its share columns only rank α_0
// (docs/results.md, "A coarser table for the pilot").
constexpr int kDefaultPilotCellsAcross = 16;

// The shape of the envmap technique's pdf (`--envmap-pdf`).
// `Optimal` is [Kar19] eq. 9 for each pixel's own BRDF and envmap share (a bank of
// tables, host/distributions/OptimalBank.h); `PixelOptimal` eq. 9 built by each pixel
// for its own normal, view, BRDF and α_0 at run time (kernels/pixel_optimal.h).
struct EnvmapPdf {
  enum class Kind { Plain, Compensated, Optimal, PixelOptimal };
  Kind kind = Kind::Plain;
  // C of [Kar19] eq. 14: the envmap technique's share of the samples, in (0, 1].
  double envmapFraction = 0.5;
  // PixelOptimal: its cells across the map (half as many down), a power of two
  // (distributions/EnvmapDistribution.h, pixelCellLog2); and those of the table built
  // by the stages that keep statistics (the pilot's), at most cellsAcross.
  int cellsAcross = kDefaultPixelCellsAcross;
  int pilotCellsAcross = kDefaultPilotCellsAcross;

  bool plain() const { return kind == Kind::Plain; }
  bool compensated() const { return kind == Kind::Compensated; }
  bool optimal() const { return kind == Kind::Optimal; }
  bool pixelOptimal() const { return kind == Kind::PixelOptimal; }
};

// "plain", "compensated", "compensated:C" with 0 < C ≤ 1, "optimal", "optimal-pixel",
// "optimal-pixel:N" with N cells across, a power of two in [kMinPixelCellsAcross,
// kMaxPixelCellsAcross], and the pilot's min(N, kDefaultPilotCellsAcross), or
// "optimal-pixel:N/P" with the pilot's P, a power of two from kMinPixelCellsAcross to N;
// throws InputError, naming `option`, otherwise.
EnvmapPdf parseEnvmapPdf(const std::string& spec, const std::string& option = "--envmap-pdf");

// "plain", "compensated:C", "optimal", "optimal-pixel" (the default cells),
// "optimal-pixel:N" or "optimal-pixel:N/P", which parseEnvmapPdf reads back.
std::string envmapPdfName(const EnvmapPdf& pdf);

// L̄ of [Kar19] eq. 14: the luminance of a W×H lat-long map (row-major, row 0 at the
// zenith) averaged over the sphere's solid angle, with each texel's exact solid angle
// (2π/W)(cos θ_top − cos θ_bottom). Procedural maps store solid-angle averages per
// texel, so for cos^K θ this is 1/(2(K+1)) up to rounding.
double solidAngleMeanLuminance(const std::vector<double>& luminance, int width, int height);

// [Kar19] eq. 14 before normalisation: max(0, L − 2(1−C)·L̄). The subtraction runs in
// double; a difference within 1e-6 of the threshold is rounding of L̄'s sum over the
// texels (a constant map at C = 0.5), not radiance, and counts as 0.
double compensatedLuminance(double luminance, double meanLuminance, double envmapFraction);

// [Kar19] eq. 5 clamped as in eq. 6, before normalisation: the free pdf p that makes
// c p + q ∝ f where it can. q = Σ of the other techniques' fractions × pdfs.
double misCompensated(double f, double q, double F, double c);

// [Kar19] eq. 9: the optimal free pdf for the Lagrange multiplier λ.
double optimalFree(double f, double q, double lambda, double c);

struct OptimalLambda {
  double lambda = 0, lower = 0, upper = 0;  // eq. 10: c F² ≤ λ ≤ F²/c
};

// The λ of eq. 9 that makes Σ_i w_i p*(x_i) = 1, by bisection within eq. 10's bounds
// (∫ p* falls as λ grows). f_i, q_i are densities at nodes of weight w_i, F = Σ w_i f_i.
OptimalLambda solveOptimalLambda(const double* f, const double* q, const double* w, std::size_t n, double F, double c);

}  // namespace misalloc
