// Meshes (scene/Mesh.h): a tessellated sphere and a quad seen by the pinhole camera give
// the frames the test computes itself from the same rays at the exact shapes; a mesh in
// Mitsuba's world gives the frames of the same mesh in misalloc's; bad meshes and cameras
// are refused.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "CliRunner.h"
#include "Constants.h"
#include "Error.h"
#include "VectorMath.h"
#include "scene/Mesh.h"
#include "scene/Scene.h"

using namespace misalloc;
namespace fs = std::filesystem;
using namespace misalloc::test;

namespace {

// The ray through pixel (x, y)'s centre of a camera at `origin` looking at `target`, image
// up towards z, vertical field of view `fov` degrees.
Vec3d pixelRay(Vec3d origin, Vec3d target, double fov, int w, int h, int x, int y) {
  const Vec3d f = unit(sub(target, origin)), r = unit(cross(f, {0, 0, 1})), u = cross(r, f);
  const double ty = std::tan(fov * kPi / 360), tx = ty * w / h;
  const double sx = (2 * (x + 0.5) / w - 1) * tx, sy = (1 - 2 * (y + 0.5) / h) * ty;
  return unit({f[0] + sx * r[0] + sy * u[0], f[1] + sx * r[1] + sy * u[1], f[2] + sx * r[2] + sy * u[2]});
}

// A unit sphere as an OBJ of nu × nv quads split in two, its normals its positions.
void writeSphereObj(const std::string& path, int nu, int nv) {
  std::ofstream f(path);
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double t = kPi * j / nv, p = 2 * kPi * i / nu;
      const Vec3d v{std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
      f << fmt::format("v {} {} {}\nvn {} {} {}\n", v[0], v[1], v[2], v[0], v[1], v[2]);
    }
  auto corner = [&](int i, int j) { return j * (nu + 1) + i + 1; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = corner(i, j), b = corner(i + 1, j), c = corner(i, j + 1), d = corner(i + 1, j + 1);
      f << fmt::format("f {0}//{0} {1}//{1} {2}//{2}\nf {2}//{2} {1}//{1} {3}//{3}\n", a, c, b, d);
    }
}

// The square [-1, 1]² in the plane of axes (a, b) at 0 on the third, as an ASCII PLY.
void writeQuadPly(const std::string& path, int a, int b) {
  std::ofstream f(path);
  f << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (auto [s, t] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    double v[3] = {0, 0, 0};
    v[a] = s, v[b] = t;
    f << fmt::format("{} {} {}\n", v[0], v[1], v[2]);
  }
  f << "3 0 1 2\n3 0 2 3\n";
}

// The angle between two directions, in radians: by the chord, well conditioned near 0.
double angleBetween(const Vec3f& a, Vec3d b) {
  const Vec3d d = sub(unit({a[0], a[1], a[2]}), unit(b));
  return 2 * std::asin(std::min(1.0, std::sqrt(dot(d, d)) / 2));
}

}  // namespace

TEST_CASE("a tessellated sphere seen by the pinhole camera: its disc and its normals", "[mesh]") {
  TempDir dir("mesh_sphere");
  const std::string obj = (dir.path / "sphere.obj").string();
  writeSphereObj(obj, 96, 48);
  const Vec3d origin{4, 1, 1.5}, target{0.1, 0, 0};
  const int w = 64, h = 48;
  GBufferOptions camera;
  camera.cameraOrigin = "4,1,1.5";
  const GBufferImage seen = rasteriseMesh({obj, "0.1,0,0", 35}, camera, w, h);
  size_t disagree = 0, covered = 0;
  double worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = size_t(y) * w + x;
      // The exact sphere along the same ray: |o + t d| = 1.
      const Vec3d d = pixelRay(origin, target, 35, w, h, x, y);
      const double b = dot(origin, d), c = dot(origin, origin) - 1, disc = b * b - c;
      const bool hit = disc > 0;
      covered += hit;
      if (hit != bool(seen.geometry.covered[p])) {
        ++disagree;
        continue;
      }
      if (!hit) continue;
      const double t = -b - std::sqrt(disc);
      const Vec3d normal = {origin[0] + t * d[0], origin[1] + t * d[1], origin[2] + t * d[2]};
      // Near the rim a facet's chord misses the sphere's limb: compare where it faces us.
      if (-dot(normal, d) > 0.2) worst = std::max(worst, angleBetween(seen.geometry.pixels[p].normal, normal));
    }
  CHECK(covered > 300);
  CHECK(disagree < 2 * kPi * std::sqrt(covered / kPi) * 0.2);  // a few rim pixels
  CHECK(worst < 0.01);                                         // radians: smooth normals, not facets
}

TEST_CASE("a quad in misalloc's world and in Mitsuba's gives the same frames", "[mesh]") {
  TempDir dir("mesh_quad");
  const std::string misallocQuad = (dir.path / "z.ply").string(), mitsubaQuad = (dir.path / "y.ply").string();
  writeQuadPly(misallocQuad, 0, 1);  // z = 0, normal +z
  writeQuadPly(mitsubaQuad, 2, 0);   // Mitsuba's y = 0 plane: its up is y
  GBufferOptions a, b;
  a.cameraOrigin = "0.5,-2,3";
  b.convention = "mitsuba";
  b.cameraOrigin = "-2,3,-0.5";  // (x, y, z) = (0.5, -2, 3) in Mitsuba's world: (y, z, -x)
  const GBufferImage za = rasteriseMesh({misallocQuad, "0,0,0", 50}, a, 40, 30);
  const GBufferImage yb = rasteriseMesh({mitsubaQuad, "0,0,0", 50}, b, 40, 30);
  CHECK(za.geometry.covered == yb.geometry.covered);
  size_t mismatches = 0, covered = 0;
  for (size_t p = 0; p < za.geometry.pixels.size(); ++p) {
    if (!za.geometry.covered[p]) continue;
    ++covered;
    mismatches +=
        za.geometry.pixels[p].normal != Vec3f{0, 0, 1} ||
        angleBetween(yb.geometry.pixels[p].normal, {0, 0, 1}) > 1e-6 ||
        angleBetween(yb.geometry.pixels[p].mirror, {za.geometry.pixels[p].mirror[0], za.geometry.pixels[p].mirror[1],
                                                    za.geometry.pixels[p].mirror[2]}) > 1e-5;
  }
  CHECK(covered > 200);
  CHECK(mismatches == 0);
}

TEST_CASE("bad meshes and cameras are refused naming the problem", "[mesh][safety]") {
  TempDir dir("mesh_bad");
  const std::string quad = (dir.path / "q.ply").string(), junk = (dir.path / "junk.obj").string();
  writeQuadPly(quad, 0, 1);
  std::ofstream(junk) << "this is not a mesh\n";
  GBufferOptions camera;
  camera.cameraOrigin = "0,0,3";
  CHECK_THROWS_WITH(rasteriseMesh({(dir.path / "none.obj").string(), "0,0,0", 40}, camera, 8, 8),
                    Catch::Contains("no such file"));
  CHECK_THROWS_WITH(rasteriseMesh({junk, "0,0,0", 40}, camera, 8, 8), Catch::Contains("--mesh"));
  CHECK_THROWS_WITH(rasteriseMesh({quad, "0,0,0", 180}, camera, 8, 8), Catch::Contains("--fov 180"));
  CHECK_THROWS_WITH(rasteriseMesh({quad, "0,0,3", 40}, camera, 8, 8), Catch::Contains("looks nowhere"));
  CHECK_THROWS_WITH(rasteriseMesh({quad, "0,0,6", 40}, camera, 8, 8), Catch::Contains("sees none of it"));
  CHECK_THROWS_WITH(rasteriseMesh({quad, "0,0,0", 40}, GBufferOptions{}, 8, 8),
                    Catch::Contains("needs --camera-origin"));
  auto r = misalloc::test::runMisalloc(
      fmt::format("render --mesh {} --camera-origin 0,0,3 --view 10 --out {}", quad, (dir.path / "x.exr").string()));
  CHECK(r.exitCode == 2);
  CHECK(r.output.find("--mesh with --view") != std::string::npos);
}

TEST_CASE("the shipped mesh is found by its name, and renders its blob and its ground", "[mesh]") {
  const std::string blobPath = resolveMeshSpec("blob");
  CHECK(fs::path(blobPath).filename() == "blob.obj");
  CHECK(fs::path(blobPath).parent_path().filename() == "meshes");
  CHECK(fs::is_regular_file(blobPath));
  CHECK(resolveMeshSpec("my/own.ply") == "my/own.ply");
  CHECK_THROWS_WITH(resolveMeshSpec("bunny"), Catch::Contains("no shipped mesh of that name"));
  GBufferOptions camera;
  camera.cameraOrigin = "4,-3,2";
  const GBufferImage seen = rasteriseMesh({blobPath, "0,0,-0.2", 45}, camera, 48, 32);
  // The blob's upper half faces the camera, the ground up: both kinds of normal, and
  // the sky above the horizon as background.
  int ground = 0, blob = 0, background = 0;
  for (size_t p = 0; p < seen.geometry.covered.size(); ++p) {
    if (!seen.geometry.covered[p]) {
      ++background;
      continue;
    }
    const Vec3f& n = seen.geometry.pixels[p].normal;
    (n[2] > 0.9999f && std::abs(n[0]) < 1e-4f && std::abs(n[1]) < 1e-4f ? ground : blob) += 1;
  }
  CHECK(ground > 100);
  CHECK(blob > 100);
  CHECK(background > 0);
}
