#include "scene/SceneGeometry.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "Error.h"

namespace misalloc {

bool SceneGeometry::flat() const {
  const Vec3f up{0.0f, 0.0f, 1.0f};
  return std::all_of(pixels.begin(), pixels.end(),
                     [&](const PixelFrame& f) { return f.normal == up && f.mirror == pixels.front().mirror; });
}

bool SceneGeometry::hasBackground() const { return coveredPixels() < covered.size(); }

std::size_t SceneGeometry::coveredPixels() const { return std::size_t(std::count(covered.begin(), covered.end(), 1)); }

std::vector<float> SceneGeometry::alpha() const {
  if (!hasBackground()) return {};
  return std::vector<float>(covered.begin(), covered.end());
}

Vec3f mirrorDirection(const Vec3f& n, const Vec3f& v) {
  const double d = 2.0 * (double(n[0]) * v[0] + double(n[1]) * v[1] + double(n[2]) * v[2]);
  return {float(d * n[0] - v[0]), float(d * n[1] - v[1]), float(d * n[2] - v[2])};
}

SceneGeometry planeGeometry(int pixels, double viewThetaDegrees, double viewPhiDegrees) {
  if (!(viewThetaDegrees >= 0 && viewThetaDegrees < 90))
    throw InputError(fmt::format("--view {}: the view's polar angle must lie in [0, 90) degrees", viewThetaDegrees));
  const double t = viewThetaDegrees * M_PI / 180, p = viewPhiDegrees * M_PI / 180;
  const Vec3f up{0.0f, 0.0f, 1.0f};
  const Vec3f view{float(std::sin(t) * std::cos(p)), float(std::sin(t) * std::sin(p)), float(std::cos(t))};
  SceneGeometry g;
  g.pixels.assign(size_t(pixels), PixelFrame{up, mirrorDirection(up, view)});
  g.covered.assign(size_t(pixels), 1);
  return g;
}

}  // namespace misalloc
