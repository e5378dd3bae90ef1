#pragma once
#include <string>
#include <vector>

namespace misalloc {

// Lafortune–Phong parameters per pixel (kernels/phong.h, PhongParams).
struct PhongParameters {
  float rhoD, rhoS, n;
};

// A W×H image of BRDF parameters: the surface whose direct lighting is rendered.
struct BrdfGrid {
  std::string spec;
  int width = 0, height = 0;
  std::vector<PhongParameters> pixels;  // row-major, row 0 at the top

  const PhongParameters& at(int x, int y) const { return pixels[size_t(y) * width + x]; }
};

// [HS14] Sec. 5.2: ρd(y) = (1−y)², ρs = 1−ρd, n(x) = −1 − 0.111211/(0.1 x^0.2 − 0.101101).
float seed000Exponent(float x);

// spec: "seed000"; "general:RD0,RD1,N0,N1" (ρd from RD0 at the top to RD1 at the
// bottom, ρs = 1−ρd, n log-spaced from N0 at the left to N1 at the right, up to 10⁵);
// "uniform:RD,RS,N" (one BRDF everywhere). Throws InputError on a bad spec.
BrdfGrid makeBrdfGrid(const std::string& spec, int width, int height);

}  // namespace misalloc
