#pragma once
// The distant lighting: a lat-long radiance map read from an EXR file or rasterised
// from a procedural description.
#include <string>

#include "scene/ExrIO.h"

namespace misalloc {

// Lat-long layout as in kernels/envmap.h: row 0 is the zenith, texel (col, row)
// covers φ ∈ 2π[col, col+1)/W and θ ∈ π[row, row+1)/H, with z up.
struct Envmap {
  RgbImage image;
  // ≥ 0: the radiance is analytically cos^K θ (white) on the upper hemisphere and 0
  // below it ([HS14] App. D); the image is then that function rasterised and only
  // shapes the sampling pdf. < 0: the image is the radiance.
  float coskExponent = -1;
  std::string description;  // for logs and reports, e.g. "sun:40,90,0.5,1e+05 (512×256)"
};

// spec is one of
//   PATH            an OpenEXR file (see readExr; `warnings` receives its repairs)
//   constant        radiance 1 everywhere
//   constant:R      radiance R ≥ 0 everywhere
//   cosk:K          cos^K θ on the upper hemisphere, 0 below, K ≥ 0 ([HS14] App. D)
//   sun             sun:40,90,0.5,1e5
//   sun:THETA,PHI,RADIUS,RATIO
//                   a bluish sky brightening from zenith to horizon over a dim ground,
//                   plus a white disc centred at polar angle THETA and azimuth PHI (φ
//                   above) of angular RADIUS, all in degrees, whose luminance is RATIO
//                   times the sky's brightest; the disc's power is exact at any width
// Procedural maps are proceduralWidth × proceduralWidth/2 texels, each the solid-angle
// average of the radiance over the texel. Throws InputError for a bad spec or file.
Envmap makeEnvmap(const std::string& spec, int proceduralWidth = 512, ReadWarnings* warnings = nullptr);

// A map given as texels in the layout above (the Python module's array), checked as a
// file's are (checkImageValues; radiance that would overflow float refused); `name`
// stands for it in messages and reports.
Envmap envmapFromTexels(RgbImage texels, const std::string& name, ReadWarnings* warnings = nullptr);

}  // namespace misalloc
