#pragma once
// MIS compensation [Kar19]: when envmap sampling is combined with BRDF sampling by
// MIS, the envmap pdf should cover what BRDF sampling leaves uncovered, not the whole
// radiance. The practical, normal-independent form ([Kar19] eq. 14) subtracts a
// constant from the luminance before tabulating it.
#include <string>
#include <vector>

namespace misalloc {

// The shape of the envmap technique's pdf (`--envmap-pdf`).
struct EnvmapPdf {
  enum class Kind { Plain, Compensated };
  Kind kind = Kind::Plain;
  // C of [Kar19] eq. 14: the envmap technique's share of the samples, in (0, 1].
  double envmapFraction = 0.5;

  bool compensated() const { return kind == Kind::Compensated; }
};

// "plain", "compensated" or "compensated:C" with 0 < C ≤ 1; throws InputError,
// naming `option`, otherwise.
EnvmapPdf parseEnvmapPdf(const std::string& spec, const std::string& option = "--envmap-pdf");

// "plain" or "compensated:C", which parseEnvmapPdf reads back.
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

}  // namespace misalloc
