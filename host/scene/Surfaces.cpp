#include "scene/Surfaces.h"

#include <cmath>
#include <numeric>

#include "Constants.h"

namespace misalloc {
namespace {

bool closeBrdfs(const PhongParameters& a, const PhongParameters& b) {
  const double exponentRatio = (double(a.n) + 1) / (double(b.n) + 1);
  return std::abs(a.rhoD - b.rhoD) < kSurfaceEdgeAlbedo && std::abs(a.rhoS - b.rhoS) < kSurfaceEdgeAlbedo &&
         exponentRatio < kSurfaceEdgeExponentRatio && exponentRatio > 1 / kSurfaceEdgeExponentRatio;
}

bool closeNormals(const Vec3f& a, const Vec3f& b) {
  static const double minCos = std::cos(kSurfaceEdgeDegrees * kPi / 180);
  return double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2] > minCos;
}

// Union–find over pixel indices, the root the smaller index.
int root(std::vector<int>& parent, int p) {
  while (parent[size_t(p)] != p) p = parent[size_t(p)] = parent[size_t(parent[size_t(p)])];
  return p;
}

void join(std::vector<int>& parent, int p, int q) {
  const int a = root(parent, p), b = root(parent, q);
  if (a != b) parent[size_t(std::max(a, b))] = std::min(a, b);
}

}  // namespace

std::vector<int32_t> labelSurfaces(const SceneGeometry& geometry, const BrdfGrid& grid) {
  const int width = grid.width, height = grid.height, pixels = width * height;
  std::vector<int> parent(static_cast<size_t>(pixels));
  std::iota(parent.begin(), parent.end(), 0);
  auto sameSurface = [&](int p, int q) {
    return geometry.covered[size_t(p)] && geometry.covered[size_t(q)] &&
           closeNormals(geometry.pixels[size_t(p)].normal, geometry.pixels[size_t(q)].normal) &&
           closeBrdfs(grid.pixels[size_t(p)], grid.pixels[size_t(q)]);
  };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int p = y * width + x;
      if (x + 1 < width && sameSurface(p, p + 1)) join(parent, p, p + 1);
      if (y + 1 < height && sameSurface(p, p + width)) join(parent, p, p + width);
    }
  std::vector<int32_t> labels(size_t(pixels), -1), labelOfRoot(size_t(pixels), -1);
  int32_t next = 0;
  for (int p = 0; p < pixels; ++p) {
    if (!geometry.covered[size_t(p)]) continue;
    int32_t& label = labelOfRoot[size_t(root(parent, p))];
    if (label < 0) label = next++;
    labels[size_t(p)] = label;
  }
  return labels;
}

}  // namespace misalloc
