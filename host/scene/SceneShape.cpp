#include "scene/SceneShape.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "Error.h"
#include "NumberList.h"

namespace misalloc {
namespace {

constexpr int kDefaultSpheres = 4;
// A sphere's radius in its square: a margin, so that neighbours do not touch.
constexpr double kSphereFill = 0.9;

struct Vec3d {
  double x, y, z;
};

Vec3d operator*(double s, Vec3d v) { return {s * v.x, s * v.y, s * v.z}; }
Vec3d operator+(Vec3d a, Vec3d b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3d cross(Vec3d a, Vec3d b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
Vec3d normalized(Vec3d v) { return (1 / std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z)) * v; }
Vec3f toFloat(Vec3d v) { return {float(v.x), float(v.y), float(v.z)}; }

// An orthographic camera: ω_o towards it, and the image's right and up.
struct Camera {
  Vec3d view, right, up;
};

Camera cameraAlong(double thetaDegrees, double phiDegrees) {
  const double t = thetaDegrees * M_PI / 180, p = phiDegrees * M_PI / 180;
  Camera c;
  c.view = {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
  // Image up towards z, or towards y where the camera looks along z.
  const Vec3d reference = std::abs(c.view.z) > 0.999 ? Vec3d{0, 1, 0} : Vec3d{0, 0, 1};
  c.right = normalized(cross(-1.0 * c.view, reference));
  c.up = cross(c.right, -1.0 * c.view);
  return c;
}

// A sphere's disc in the image: its centre and radius in pixels.
struct Disc {
  double x, y, radius;
};

// Where pixel (x, y) sees the disc's sphere, if it does: its normal, and (u, v) over the
// sphere's visible half, u by longitude from the left limb, v by latitude from the top.
bool seeSphere(const Camera& camera, const Disc& disc, int x, int y, Vec3f& normal, SurfaceUv& uv) {
  const double a = (x + 0.5 - disc.x) / disc.radius, b = (disc.y - (y + 0.5)) / disc.radius;
  const double r2 = a * a + b * b;
  if (r2 >= 1) return false;
  const double c = std::sqrt(1 - r2);
  normal = toFloat(normalized(a * camera.right + b * camera.up + c * camera.view));
  uv = {std::atan2(a, c) / M_PI + 0.5, 0.5 - std::asin(b) / M_PI};
  return true;
}

ShapeImage spheresImage(const SceneShape& shape, int width, int height, const Camera& camera) {
  const double cellWidth = double(width) / shape.columns, cellHeight = double(height) / shape.rows;
  const double radius = 0.5 * kSphereFill * std::min(cellWidth, cellHeight);
  if (radius < 2)
    throw InputError(
        fmt::format("--scene with {}x{} spheres on {}x{} pixels: each sphere would be under 4 pixels "
                    "across; use a larger --size or fewer spheres",
                    shape.columns, shape.rows, width, height));
  const Vec3f view = toFloat(camera.view), up{0.0f, 0.0f, 1.0f};
  ShapeImage out;
  out.uv = pixelCentres(width, height);
  out.geometry.pixels.assign(out.uv.size(), PixelFrame{up, up});
  out.geometry.covered.assign(out.uv.size(), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      // The cell the pixel lies in holds the only sphere it can see.
      const int i = std::min(shape.columns - 1, int((x + 0.5) / cellWidth));
      const int j = std::min(shape.rows - 1, int((y + 0.5) / cellHeight));
      const Disc disc{(i + 0.5) * cellWidth, (j + 0.5) * cellHeight, radius};
      const size_t p = size_t(y) * width + x;
      Vec3f normal;
      SurfaceUv onSphere;
      if (!seeSphere(camera, disc, x, y, normal, onSphere)) continue;
      out.geometry.pixels[p] = PixelFrame{normal, mirrorDirection(normal, view)};
      out.geometry.covered[p] = 1;
      // One sphere, the whole grid over it; many, each the grid's value at its cell.
      out.uv[p] =
          shape.kind == SceneShape::Sphere ? onSphere : SurfaceUv{(i + 0.5) / shape.columns, (j + 0.5) / shape.rows};
    }
  return out;
}

}  // namespace

SceneShape parseSceneShape(const std::string& spec) {
  if (spec == "plane") return {SceneShape::Plane, 1, 1};
  if (spec == "sphere") return {SceneShape::Sphere, 1, 1};
  if (spec == "spheres") return {SceneShape::Spheres, kDefaultSpheres, kDefaultSpheres};
  if (spec.rfind("spheres:", 0) == 0) {
    const std::string counts = spec.substr(8);
    const size_t x = counts.find('x');
    std::vector<double> n;
    if (x != std::string::npos)
      n = {parseNumberList("--scene", spec, counts.substr(0, x), 1, "expected spheres:COLUMNSxROWS")[0],
           parseNumberList("--scene", spec, counts.substr(x + 1), 1, "expected spheres:COLUMNSxROWS")[0]};
    if (n.size() != 2 || n[0] != std::floor(n[0]) || n[1] != std::floor(n[1]) || n[0] < 1 || n[1] < 1 || n[0] > 64 ||
        n[1] > 64)
      throw InputError(fmt::format("--scene {}: expected spheres:COLUMNSxROWS, each a whole number in [1, 64]", spec));
    return {SceneShape::Spheres, int(n[0]), int(n[1])};
  }
  throw InputError(fmt::format("unknown --scene '{}' (expected plane, sphere, spheres or spheres:COLUMNSxROWS)", spec));
}

double defaultViewTheta(const SceneShape& shape) { return shape.kind == SceneShape::Plane ? 0.0 : 75.0; }

ShapeImage shapeImage(const SceneShape& shape, int width, int height, double viewThetaDegrees, double viewPhiDegrees) {
  if (shape.kind == SceneShape::Plane)
    return {planeGeometry(width * height, viewThetaDegrees, viewPhiDegrees), pixelCentres(width, height)};
  if (!(viewThetaDegrees >= 0 && viewThetaDegrees <= 180))
    throw InputError(fmt::format("--view {}: the view's polar angle must lie in [0, 180] degrees", viewThetaDegrees));
  const Camera camera = cameraAlong(viewThetaDegrees, viewPhiDegrees);
  return spheresImage(shape, width, height, camera);
}

}  // namespace misalloc
