#pragma once
#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace misalloc {

using Vec3f = std::array<float, 3>;

// A pixel's shading normal and the mirror direction of its view about it, in the map's
// frame (kernels/envmap.h: z up). Kernel side: ShadingPoint (kernels/estimator.h).
struct PixelFrame {
  Vec3f normal, mirror;
};

// Where every pixel's shading point faces and how it is seen: the surface under the
// BRDF grid.
struct SceneGeometry {
  std::vector<PixelFrame> pixels;  // row-major as the BRDF grid, row 0 at the top
  // Per pixel: 1 where a surface is seen, 0 for the background, which takes no samples
  // and counts in no error (its frame is z, never sampled).
  std::vector<unsigned char> covered;

  bool hasBackground() const;
  std::size_t coveredPixels() const;
  // The image's alpha (RgbImage::alpha): none without background, else 1 or 0 per pixel.
  std::vector<float> alpha() const;

  // [HS14] Sec. 5.2's scene: every pixel's normal is z and its view the same. The
  // optimal pdf's bank and the product tables are built for that one frame.
  bool flat() const;
};

// The mirror direction of ω_o about n, 2(n·ω_o)n − ω_o, for unit n and ω_o.
Vec3f mirrorDirection(const Vec3f& normal, const Vec3f& view);

// A plane (normal z) seen from ω_o at polar angle θ and azimuth φ (degrees) at each of
// its pixels, as by a distant camera. Throws InputError where θ is not in [0, 90).
SceneGeometry planeGeometry(int pixels, double viewThetaDegrees, double viewPhiDegrees);

}  // namespace misalloc
