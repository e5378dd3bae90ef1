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

// The specs of a grid read from a G-buffer's BRDF channels (scene/GBuffer.h): the Phong
// exponent given, or mapped from a roughness.
constexpr const char* kGBufferBrdf = "gbuffer:rho_d,rho_s,phong_n";
constexpr const char* kGBufferRoughnessBrdf = "gbuffer:rho_d,rho_s,roughness";
inline bool isGBufferBrdf(const std::string& spec) { return spec.rfind("gbuffer:", 0) == 0; }

// Where a pixel reads the grid's pattern: (u, v) ∈ [0,1]², u to the right, v down.
struct SurfaceUv {
  double u, v;
};

// The grid's pattern read at each pixel's `uv` (row-major, width × height): spec
// "seed000"; "general:RD0,RD1,N0,N1" (ρd from RD0 at v = 0 to RD1 at v = 1, ρs = 1−ρd,
// n log-spaced from N0 at u = 0 to N1 at u = 1, up to 10⁵); "uniform:RD,RS,N" (one BRDF
// everywhere). Throws InputError on a bad spec.
BrdfGrid makeBrdfGrid(const std::string& spec, int width, int height, const std::vector<SurfaceUv>& uv);

// Each pixel's centre in (u, v): the image itself as the surface.
std::vector<SurfaceUv> pixelCentres(int width, int height);

// The pattern laid over the image itself, each pixel at its centre: [HS14] Sec. 5.2's plane.
BrdfGrid makeBrdfGrid(const std::string& spec, int width, int height);

}  // namespace misalloc
