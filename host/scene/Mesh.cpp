#include "scene/Mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <Eigen/Dense>
#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>
#include <limits>
#include <vector>

#include "Error.h"
#include "NumberList.h"

namespace misalloc {
namespace {

using Point = Eigen::Vector3d;

// Every triangle's corners and their smooth normals, in the map's frame.
struct Triangles {
  std::vector<Point> positions, normals;  // three per triangle
};

// A point or direction of the convention's world in the map's frame.
Point mapPoint(GBufferConvention convention, const Point& v) {
  const Vec3d m = toMapFrame(convention, {v.x(), v.y(), v.z()});
  return Point(m[0], m[1], m[2]);
}

Point toPoint(const aiVector3D& v) { return Point(v.x, v.y, v.z); }

Triangles readTriangles(const std::string& path, GBufferConvention convention) {
  std::error_code ignored;
  if (!std::filesystem::exists(path, ignored)) throw InputError(fmt::format("--mesh '{}': no such file", path));
  // A FIFO or a device would block the read, or never end.
  if (!std::filesystem::is_regular_file(path, ignored))
    throw InputError(fmt::format("--mesh '{}' is not a regular file", path));
  Assimp::Importer importer;
  // Smooth normals where the file has none; every node's transform applied.
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                                     aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices);
  if (!scene) throw InputError(fmt::format("--mesh '{}': cannot read it: {}", path, importer.GetErrorString()));
  Triangles t;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    if (!mesh->HasNormals()) continue;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      for (unsigned k = 0; k < 3; ++k) {
        t.positions.push_back(mapPoint(convention, toPoint(mesh->mVertices[face.mIndices[k]])));
        t.normals.push_back(mapPoint(convention, toPoint(mesh->mNormals[face.mIndices[k]])));
      }
    }
  }
  if (t.positions.empty()) throw InputError(fmt::format("--mesh '{}' holds no triangles", path));
  return t;
}

Point parsePoint(const std::string& option, const std::string& value) {
  const auto v = parseNumberList(option, value, value, 3, "expected X,Y,Z");
  return Point(v[0], v[1], v[2]);
}

// A pinhole camera: each pixel's ray through its centre.
struct PinholeCamera {
  Point origin, forward, right, up;
  double tanX, tanY;
  int width, height;

  Point ray(int x, int y) const {
    const double sx = (2 * (x + 0.5) / width - 1) * tanX, sy = (1 - 2 * (y + 0.5) / height) * tanY;
    return (forward + sx * right + sy * up).normalized();
  }
  // The pixel (x, y) a point projects to, as doubles; false behind the camera.
  bool project(const Point& p, double& x, double& y) const {
    const Point d = p - origin;
    const double z = d.dot(forward);
    if (!(z > 0)) return false;
    x = (d.dot(right) / z / tanX + 1) * width / 2;
    y = (1 - d.dot(up) / z / tanY) * height / 2;
    return true;
  }
};

PinholeCamera pinholeCamera(const Point& origin, const Point& target, double fovDegrees, int width, int height) {
  if (!(fovDegrees > 0 && fovDegrees < 180))
    throw InputError(fmt::format("--fov {}: the vertical field of view must lie in (0, 180) degrees", fovDegrees));
  const Point toTarget = target - origin;
  if (!(toTarget.norm() > 0)) throw InputError("--camera-target is --camera-origin: the camera looks nowhere");
  PinholeCamera c;
  c.origin = origin;
  c.forward = toTarget.normalized();
  const Point worldUp = std::abs(c.forward.z()) > 0.999 ? Point(0, 1, 0) : Point(0, 0, 1);
  c.right = c.forward.cross(worldUp).normalized();
  c.up = c.right.cross(c.forward);
  c.tanY = std::tan(fovDegrees * M_PI / 360);
  c.tanX = c.tanY * width / height;
  c.width = width;
  c.height = height;
  return c;
}

// Möller–Trumbore: the ray's distance to the triangle and the hit's barycentrics (b1, b2).
bool hitTriangle(const Point& origin, const Point& ray, const Point* corner, double& t, double& b1, double& b2) {
  const Point e1 = corner[1] - corner[0], e2 = corner[2] - corner[0], h = ray.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-14) return false;
  const Point s = origin - corner[0];
  b1 = s.dot(h) / det;
  if (b1 < 0 || b1 > 1) return false;
  const Point q = s.cross(e1);
  b2 = ray.dot(q) / det;
  if (b2 < 0 || b1 + b2 > 1) return false;
  t = e2.dot(q) / det;
  return t > 0;
}

}  // namespace

GBufferImage rasteriseMesh(const MeshOptions& mesh, const GBufferOptions& gbuffer, int width, int height) {
  const GBufferConvention convention = parseGBufferConvention(gbuffer.convention);
  if (gbuffer.cameraOrigin.empty())
    throw InputError(fmt::format("--mesh {}: the camera needs --camera-origin X,Y,Z", mesh.path));
  const PinholeCamera camera = pinholeCamera(mapPoint(convention, parsePoint("--camera-origin", gbuffer.cameraOrigin)),
                                             mapPoint(convention, parsePoint("--camera-target", mesh.target)),
                                             mesh.verticalFovDegrees, width, height);
  const Triangles triangles = readTriangles(mesh.path, convention);

  // Each triangle tried at the pixels its projection covers (all of them where a corner
  // lies behind the camera); the nearest hit wins.
  const size_t pixels = size_t(width) * size_t(height);
  std::vector<double> depth(pixels, std::numeric_limits<double>::infinity());
  std::vector<long> hitTriangleOf(pixels, -1);
  std::vector<std::array<double, 2>> hitBarycentrics(pixels);
  for (size_t tri = 0; tri < triangles.positions.size() / 3; ++tri) {
    const Point* corner = &triangles.positions[3 * tri];
    double x0 = width, x1 = -1, y0 = height, y1 = -1;
    bool projected = true;
    for (int k = 0; k < 3; ++k) {
      double x = 0, y = 0;
      projected = projected && camera.project(corner[k], x, y);
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    if (!projected) x0 = y0 = 0, x1 = width, y1 = height;
    const int xa = std::max(0, int(std::floor(x0)) - 1), xb = std::min(width - 1, int(std::ceil(x1)));
    const int ya = std::max(0, int(std::floor(y0)) - 1), yb = std::min(height - 1, int(std::ceil(y1)));
    for (int y = ya; y <= yb; ++y)
      for (int x = xa; x <= xb; ++x) {
        double t, b1, b2;
        const size_t p = size_t(y) * width + x;
        if (hitTriangle(camera.origin, camera.ray(x, y), corner, t, b1, b2) && t < depth[p]) {
          depth[p] = t;
          hitTriangleOf[p] = long(tri);
          hitBarycentrics[p] = {b1, b2};
        }
      }
  }

  GBufferImage out;
  out.width = width;
  out.height = height;
  const Vec3f zenith{0.0f, 0.0f, 1.0f};
  out.geometry.pixels.assign(pixels, PixelFrame{zenith, zenith});
  out.geometry.covered.assign(pixels, 0);
  for (size_t p = 0; p < pixels; ++p) {
    if (hitTriangleOf[p] < 0) continue;
    const Point* n = &triangles.normals[3 * size_t(hitTriangleOf[p])];
    const auto [b1, b2] = hitBarycentrics[p];
    Point normal = (1 - b1 - b2) * n[0] + b1 * n[1] + b2 * n[2];
    const Point view = -camera.ray(int(p % size_t(width)), int(p / size_t(width)));
    if (!(normal.norm() > 0)) continue;  // opposite corner normals: no shading normal
    normal.normalize();
    if (normal.dot(view) < 0) normal = -normal;  // two-sided
    const Vec3f nf{float(normal.x()), float(normal.y()), float(normal.z())};
    out.geometry.pixels[p] = PixelFrame{nf, mirrorDirection(nf, {float(view.x()), float(view.y()), float(view.z())})};
    out.geometry.covered[p] = 1;
  }
  if (out.geometry.coveredPixels() == 0)
    throw InputError(
        fmt::format("--mesh {}: the camera sees none of it (--camera-origin, --camera-target, --fov)", mesh.path));
  return out;
}

}  // namespace misalloc
