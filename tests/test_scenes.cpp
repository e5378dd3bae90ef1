// The built-in scenes (--scene, scene/SceneShape.h) and the background they leave: a
// sphere's pixels face the camera, each sphere of a grid has one BRDF, and pixels that see
// no surface take no samples and count in no error, through every method's render.
#include <fmt/format.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <set>
#include <tuple>

#include "BiasCheck.h"
#include "Error.h"
#include "PictureChecks.h"
#include "SceneFixtures.h"
#include "render/Reference.h"
#include "render/Render.h"
#include "report/AlphaMap.h"
#include "report/ImageMetrics.h"
#include "scene/SceneShape.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

Scene shapeScene(const std::string& shape, const std::string& envmap, const std::string& grid, int w, int h,
                 double viewTheta = 75, double viewPhi = 0) {
  SceneOptions o = smallSceneOptions(envmap, grid, w, h);
  o.shape = shape;
  o.viewTheta = viewTheta;
  o.viewPhi = viewPhi;
  return makeScene(o);
}

double dot(const Vec3f& a, const Vec3f& b) { return double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2]; }

// The mean luminance of the covered pixels and its standard error: independent estimates
// of one value.
MeanAndError coveredMean(const RgbImage& image) {
  std::vector<double> rgb;
  for (size_t p = 0; p < image.rgb.size() / 3; ++p)
    if (image.covers(p))
      rgb.insert(rgb.end(), image.rgb.begin() + ptrdiff_t(3 * p), image.rgb.begin() + ptrdiff_t(3 * p + 3));
  return pixelMean(rgb);
}

}  // namespace

TEST_CASE("a sphere's pixels face the camera, cover its disc and read the grid over its visible half", "[scenes]") {
  for (auto [theta, phi] : {std::pair{75.0, 0.0}, {0.0, 0.0}, {120.0, 200.0}}) {
    INFO(fmt::format("view {} {}", theta, phi));
    const Scene scene = shapeScene("sphere", "constant", "seed000", 64, 48, theta, phi);
    const double t = theta * kPi / 180, f = phi * kPi / 180;
    const Vec3f view{float(std::sin(t) * std::cos(f)), float(std::sin(t) * std::sin(f)), float(std::cos(t))};
    const SceneGeometry& g = scene.geometry;
    size_t covered = 0, bad = 0;
    for (size_t p = 0; p < g.pixels.size(); ++p) {
      if (!g.covered[p]) continue;
      ++covered;
      const PixelFrame& frame = g.pixels[p];
      bad += std::abs(dot(frame.normal, frame.normal) - 1) > 1e-6 || dot(frame.normal, view) < 0 ||
             std::abs(dot(frame.mirror, frame.mirror) - 1) > 1e-5 ||
             std::abs(dot(frame.mirror, frame.normal) - dot(frame.normal, view)) > 1e-5;
    }
    CHECK(bad == 0);
    // The disc of radius 0.45 of the shorter side, within its rim's pixels.
    const double radius = 0.45 * 48, area = kPi * radius * radius;
    CHECK(std::abs(double(covered) - area) < 2 * kPi * radius);
    CHECK(g.hasBackground());
    CHECK_FALSE(g.flat());
  }
  // Seen from the side, the top of the sphere faces up, its left limb away from the right.
  const Scene side = shapeScene("sphere", "constant", "seed000", 65, 65, 90, 0);
  const PixelFrame& top = side.geometry.pixels[size_t(5) * 65 + 32];
  CHECK(top.normal[2] > 0.8f);
  const PixelFrame& centre = side.geometry.pixels[size_t(32) * 65 + 32];
  CHECK(centre.normal[0] > 0.999f);
  // The grid over the visible half: the diffuse albedo (1 − v)² falls from the top down,
  // the exponent grows from left to right.
  const BrdfGrid& grid = side.grid;
  CHECK(grid.at(32, 6).rhoD > grid.at(32, 58).rhoD);
  CHECK(grid.at(6, 32).n < grid.at(58, 32).n);
}

TEST_CASE("a grid of spheres holds one BRDF per sphere, the grid's at its cell", "[scenes]") {
  const Scene scene = shapeScene("spheres:3x2", "constant", "seed000", 60, 40);
  const BrdfGrid plane = makeBrdfGrid("seed000", 3, 2);
  std::set<std::tuple<float, float, float>> brdfs;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 60; ++x) {
      if (!scene.geometry.covered[size_t(y) * 60 + x]) continue;
      const PhongParameters &p = scene.grid.at(x, y), &cell = plane.at(x / 20, y / 20);
      brdfs.insert({p.rhoD, p.rhoS, p.n});
      CHECK((p.rhoD == cell.rhoD && p.rhoS == cell.rhoS && p.n == cell.n));
    }
  CHECK(brdfs.size() == 6);
  // Between the spheres, background; none touches its neighbour.
  CHECK_FALSE(scene.geometry.covered[size_t(20) * 60 + 20]);
  CHECK_FALSE(scene.geometry.covered[size_t(10) * 60 + 20]);
}

TEST_CASE("the plane is [HS14]'s scene, as it was", "[scenes]") {
  const Scene scene = shapeScene("plane", "constant", "seed000", 12, 8, 30, 40);
  const BrdfGrid grid = makeBrdfGrid("seed000", 12, 8);
  CHECK(std::memcmp(scene.grid.pixels.data(), grid.pixels.data(), grid.pixels.size() * sizeof(PhongParameters)) == 0);
  const SceneGeometry plane = planeGeometry(96, 30, 40);
  CHECK(std::memcmp(scene.geometry.pixels.data(), plane.pixels.data(), plane.pixels.size() * sizeof(PixelFrame)) == 0);
  CHECK_FALSE(scene.geometry.hasBackground());
  CHECK(scene.geometry.alpha().empty());
  CHECK_FALSE(scene.options.perPixelGeometry());
  CHECK(envmapPdfName(defaultEnvmapPdf(scene.options)) == "optimal");
}

TEST_CASE("bad --scene specs and views are refused, naming the option", "[scenes][safety]") {
  for (const char* spec : {"cube", "spheres:", "spheres:0x3", "spheres:2.5x2", "spheres:3", "spheres:65x1", "sphere:2"})
    CHECK_THROWS_WITH(parseSceneShape(spec), Catch::Contains("--scene"));
  CHECK_THROWS_WITH(shapeScene("sphere", "constant", "seed000", 16, 16, 190), Catch::Contains("--view 190"));
  CHECK_THROWS_WITH(shapeScene("plane", "constant", "seed000", 16, 16, 90), Catch::Contains("--view 90"));
  CHECK_THROWS_WITH(shapeScene("spheres:8x8", "constant", "seed000", 24, 24), Catch::Contains("under 4 pixels"));
  // The optimal pdf and the product technique are built for one frame.
  SceneOptions o;
  o.shape = "spheres";
  o.width = o.height = 32;
  o.envmap = "constant";
  o.proceduralWidth = 64;
  CHECK(o.perPixelGeometry());
  CHECK(envmapPdfName(defaultEnvmapPdf(o)) == "optimal-pixel");
  o.envmapPdf = parseEnvmapPdf("optimal");
  CHECK_THROWS_WITH(makeScene(o), Catch::Contains("not implemented"));
  o.envmapPdf = {};
  o.product = true;
  CHECK_THROWS_WITH(
      makeScene(o),
      Catch::Contains("--product with --envmap-pdf plain and per-pixel normals or views: not implemented"));
}

TEST_CASE("background pixels take no samples and count in no error, whatever the method", "[scenes][adaptive]") {
  const Scene scene = shapeScene("spheres:2x2", "cosk:1", "seed000", 24, 24);
  const size_t pixels = size_t(scene.pixelCount()), covered = scene.geometry.coveredPixels();
  REQUIRE(covered > pixels / 2);
  REQUIRE(covered < pixels);
  struct Run {
    Method method;
    Estimator estimator;
    MisWeights weights;
  };
  const Run runs[] = {{Method::Equal, Estimator::MultiSample, MisWeights::Balance},
                      {Method::Equal, Estimator::OneSample, MisWeights::Balance},
                      {Method::Ris, Estimator::MultiSample, MisWeights::Balance},
                      {Method::Heuristic, Estimator::MultiSample, MisWeights::Balance},
                      {Method::SigmaSqrtC, Estimator::MultiSample, MisWeights::Balance},
                      {Method::Exact, Estimator::MultiSample, MisWeights::Balance},
                      {Method::Exact, Estimator::MultiSample, MisWeights::Optimal},
                      {Method::Oracle, Estimator::MultiSample, MisWeights::Balance}};
  for (const Run& run : runs) {
    INFO(fmt::format("{} estimator {} weights {}", methodName(run.method), int(run.estimator), int(run.weights)));
    AdaptiveOptions options;
    options.costs.assign(2, 1.0);
    options.oracleSamples = 32;
    options.stages = 2;
    options.weights = run.weights;
    HostSampler sampler(scene, samplerConfigFor(run.method, run.estimator, 40, options, scene.techniqueCount()));
    const Rendering r = render(sampler, run.method, options, 40, 7);
    CHECK(r.image.alpha == scene.geometry.alpha());
    size_t sampledBackground = 0, nonZeroBackground = 0, uncounted = 0;
    for (size_t p = 0; p < pixels; ++p) {
      const double taken = r.alpha[2 * p] + r.alpha[2 * p + 1];
      if (scene.geometry.covered[p]) {
        uncounted += std::abs(taken - 1) > 1e-12;
        continue;
      }
      sampledBackground += taken != 0;
      nonZeroBackground +=
          r.image.rgb[3 * p] != 0 || r.image.rgb[3 * p + 1] != 0 || r.image.rgb[3 * p + 2] != 0 || r.variance[p] != 0;
    }
    CHECK(sampledBackground == 0);
    CHECK(nonZeroBackground == 0);
    CHECK(uncounted == 0);
    // The α map's picture: red + blue = 255 where samples were split, black where none.
    const std::vector<uint8_t> picture = decodePng(encodeAlphaMaps(scene, r).png).rgb;
    size_t misdrawn = 0;
    for (size_t p = 0; p < pixels; ++p) {
      const int red = picture[3 * p], blue = picture[3 * p + 2];
      misdrawn += scene.geometry.covered[p] ? std::abs(red + blue - 255) > 1 : red + blue != 0;
    }
    CHECK(misdrawn == 0);
    // The background's empty sums fall back in every rule; they are not reported.
    CHECK(r.fallbackPixels + r.flooredPixels + r.skippedPixels <= covered);
    CHECK(r.weightsFallbacks.pixels <= covered);
  }
}

TEST_CASE("a run's errors are over the pixels it covers", "[scenes]") {
  RgbImage image{2, 2, {1, 1, 1, 2, 2, 2, 0, 0, 0, 0, 0, 0}, {1, 1, 0, 0}};
  RgbImage reference{2, 2, {1, 1, 1, 1, 1, 1, 5, 5, 5, 7, 7, 7}, {}};
  // One of the two covered pixels is off by 1 in each channel: MSE 1/2, whatever the
  // background holds.
  CHECK(rmse(image, reference) == Approx(std::sqrt(0.5)));
  CHECK(correctedMse(image, reference, {}).mse == Approx(0.5));
  CHECK(relativeMse(image, reference) == Approx(0.5 / 1.01));
  CHECK(image.coveredPixels() == 2);
}

TEST_CASE("a sphere's reference is keyed on its pixels' frames, BRDFs and coverage", "[scenes][reference]") {
  const Scene sphere = shapeScene("sphere", "constant", "seed000", 32, 32);
  const Scene one = shapeScene("spheres:1x1", "constant", "seed000", 32, 32);
  // The same disc, frames and coverage; the grid over the sphere, or its centre's BRDF.
  REQUIRE(sphere.geometry.covered == one.geometry.covered);
  CHECK(referenceKey(sphere, 64) != referenceKey(one, 64));
  CHECK(referenceKey(sphere, 64) != referenceKey(shapeScene("sphere", "constant", "seed000", 32, 32, 60), 64));
  CHECK(referenceEstimator(sphere.options) == "equal-count MIS, optimal-pixel envmap pdf");
}

TEST_CASE("under a constant map every covered pixel of a sphere is rho_d, through every method (white furnace)",
          "[scenes][unbiased]") {
  const Scene scene = shapeScene("sphere", "constant", "uniform:0.6,0,1", 20, 20, 60, 30);
  BiasFamily family(0.02);
  uint64_t seed = 300;
  for (Method method : {Method::Equal, Method::Heuristic, Method::Exact}) {
    AdaptiveOptions options;
    options.costs.assign(2, 1.0);
    addSized(family, methodName(method), 0.6, 16, 8, ++seed, [&](int spp, uint64_t sd) {
      spp = std::max(spp, 16);
      HostSampler sampler(scene,
                          samplerConfigFor(method, Estimator::MultiSample, spp, options, scene.techniqueCount()));
      return coveredMean(render(sampler, method, options, spp, sd).image);
    });
  }
  checkFamily(family);
}
