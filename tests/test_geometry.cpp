// Per-pixel geometry (kernels/estimator.h, ShadingPoint): each pixel shades in a frame
// of its own, normal and view anywhere on the sphere, while the map and its pdfs stay in
// the map's frame. Checked against values the test computes itself: the white furnace
// (under a constant map a diffuse pixel's value is ρ_d whatever its frame) and a
// quadrature on the sphere of the cos^K map × Phong BRDF × cos, for every estimator.
#include <fmt/format.h>

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "BiasCheck.h"
#include "Error.h"
#include "SceneFixtures.h"
#include "TestSize.h"
#include "VectorMath.h"
#include "render/Render.h"
#include "sampling/HostSampler.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

// Two unit vectors that make an orthonormal basis with unit `axis`.
std::array<Vec3d, 2> basisAbout(const Vec3d& axis) {
  const Vec3d helper = std::abs(axis[0]) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
  const Vec3d t = unit(cross(helper, axis));
  return {t, cross(axis, t)};
}

// ∫ g(ω) dω over the sphere by the midpoint rule on rings about `axis`, with
// 1 − cos α = 2t⁴ (rings dense near the axis, where a Phong lobe is) and φ uniform.
double sphereIntegral(const Vec3d& axis, const std::function<double(const Vec3d&)>& g) {
  constexpr int kRings = 1200, kSegments = 256;
  const auto [t, s] = basisAbout(axis);
  double sum = 0;
  for (int i = 0; i < kRings; ++i) {
    const double u = (i + 0.5) / kRings, d = 2 * std::pow(u, 4), dd = 8 * std::pow(u, 3) / kRings;
    const double cosA = 1 - d, sinA = std::sqrt(std::max(0.0, d * (2 - d)));
    for (int j = 0; j < kSegments; ++j) {
      const double phi = 2 * kPi * (j + 0.5) / kSegments;
      Vec3d w;
      for (int c = 0; c < 3; ++c) w[c] = cosA * axis[c] + sinA * (std::cos(phi) * t[c] + std::sin(phi) * s[c]);
      sum += g(w) * dd * 2 * kPi / kSegments;
    }
  }
  return sum;
}

// A pixel's value under L(ω) = max(ω_z, 0)^K ("cosk:K") with the Phong BRDF (ρ_d, ρ_s,
// n) in frame f: ∫ L f_r max(n·ω, 0) dω, the diffuse part on rings about the normal and
// the lobe's on rings about the mirror direction.
double quadratureValue(double K, double rhoD, double rhoS, double n, const PixelFrame& f) {
  const Vec3d normal = toDouble(f.normal), mirror = toDouble(f.mirror);
  auto radianceCos = [&](const Vec3d& w) {
    return (w[2] > 0 ? std::pow(w[2], K) : 0.0) * std::max(dot(normal, w), 0.0);
  };
  const double diffuse = sphereIntegral(normal, radianceCos) / kPi;
  const double lobe = sphereIntegral(
      mirror, [&](const Vec3d& w) { return std::pow(std::max(dot(mirror, w), 0.0), n) * radianceCos(w); });
  return rhoD * diffuse + rhoS * (n + 2) / (2 * kPi) * lobe;
}

// A frame off the map's axis under cos^K θ: a wall facing the horizon, a tilted surface
// seen at a grazing angle, and one facing the ground, lit only by the part of the sky
// above its horizon; the second alone at the small test size.
struct OffAxisCase {
  Vec3d normal;
  double view, K;
};

std::vector<OffAxisCase> offAxisCases() {
  if (smallTestSize()) return {{{2.0 / 7, -3.0 / 7, 6.0 / 7}, 75, 2}};
  return {{{1, 0, 0}, 30, 1}, {{2.0 / 7, -3.0 / 7, 6.0 / 7}, 75, 2}, {{0.6, 0, -0.8}, 45, 0.5}};
}

// Normal `normal` seen from `viewDegrees` off it.
PixelFrame frameAt(const Vec3d& normal, double viewDegrees) {
  const auto [t, s] = basisAbout(normal);
  const double a = viewDegrees * kPi / 180;
  Vec3f n, v;
  for (int c = 0; c < 3; ++c) n[c] = float(normal[c]), v[c] = float(std::cos(a) * normal[c] + std::sin(a) * t[c]);
  return frameSeenFrom(n, v);
}

// The off-axis case's scene with the optimal pdf per pixel under a glossy BRDF, every
// pixel in its frame; with `product`, the product technique from the pixel's cells.
constexpr double kRhoD = 0.3, kRhoS = 0.7, kN = 20;

Scene pixelOptimalOffAxisScene(const OffAxisCase& c, bool product) {
  Scene scene = smallScene(fmt::format("cosk:{}", c.K), fmt::format("uniform:{},{},{}", kRhoD, kRhoS, kN), 32, 32,
                           false, EnvmapSampler::Alias, 0, "optimal-pixel", product);
  std::fill(scene.geometry.pixels.begin(), scene.geometry.pixels.end(), frameAt(c.normal, c.view));
  return scene;
}

std::string offAxisName(const OffAxisCase& c) {
  return fmt::format("normal ({:.3f}, {:.3f}, {:.3f}) view {}° K {}", c.normal[0], c.normal[1], c.normal[2], c.view,
                     c.K);
}

MeanAndError renderMean(const Scene& scene, Method method, Estimator estimator, int spp, uint64_t seed) {
  return pixelMean(sweepSampler(scene, {estimator, 0, 0})->run(singleStagePlan(scene, method, spp), seed).rgb);
}

MeanAndError resampledMean(const Scene& scene, int spp, uint64_t seed) {
  AdaptiveOptions options;
  options.risCandidates = 3;
  HostSampler sampler(scene,
                      samplerConfigFor(Method::Ris, Estimator::MultiSample, spp, options, scene.techniqueCount()));
  return pixelMean(sampler.run(singleStagePlan(scene, Method::Ris, spp), seed).rgb);
}

// Every way of sampling a scene: each technique alone, their MIS with every estimator,
// the BRDF's lobes split, and resampled envmap candidates.
void addEveryEstimator(BiasFamily& family, const Scene& scene, const Scene& split, const std::string& what,
                       double expected, uint64_t& seed) {
  struct Run {
    const Scene* scene;
    Method method;
    Estimator estimator;
  };
  const Run runs[] = {
      {&scene, Method::Envmap, Estimator::MultiSample},     {&scene, Method::Brdf, Estimator::MultiSample},
      {&scene, Method::Equal, Estimator::MultiSample},      {&scene, Method::Equal, Estimator::OneSample},
      {&scene, Method::Equal, Estimator::CountIndependent}, {&split, Method::Equal, Estimator::MultiSample},
      {&scene, Method::Ris, Estimator::MultiSample}};
  for (const Run& r : runs) {
    const std::string name = fmt::format("{}: {} estimator {}{}", what, methodName(r.method), int(r.estimator),
                                         r.scene == &split ? ", lobes split" : "");
    addSized(family, name, expected, 16, 4, ++seed, [&](int spp, uint64_t sd) {
      return r.method == Method::Ris ? resampledMean(*r.scene, spp, sd)
                                     : renderMean(*r.scene, r.method, r.estimator, spp, sd);
    });
  }
}

}  // namespace

TEST_CASE("the sphere quadrature reproduces [HS14] eq. 6.17 in the flat frame", "[geometry]") {
  const PixelFrame flat{{0, 0, 1}, {0, 0, 1}};
  for (const auto& [K, rhoD, n] : {std::array<double, 3>{1, 0.5, 5}, {3, 0.2, 50}, {0.5, 0.05, 100}}) {
    INFO(fmt::format("K {} rhoD {} n {}", K, rhoD, n));
    CHECK(std::abs(quadratureValue(K, rhoD, 1 - rhoD, n, flat) - closedForm(rhoD, 1 - rhoD, n, K)) < 1e-5);
  }
}

TEST_CASE("under a constant map a diffuse pixel is rho_d in any frame (white furnace)", "[geometry][unbiased]") {
  BiasFamily family(0.02);
  Scene scene = smallScene("constant", "uniform:0.7,0,1", 32, 32);
  Scene split = smallScene("constant", "uniform:0.7,0,1", 32, 32, true);
  giveRandomFrames(scene, 1);
  giveRandomFrames(split, 1);
  uint64_t seed = 900;
  addEveryEstimator(family, scene, split, "random frames", 0.7, seed);
  checkFamily(family);
}

TEST_CASE("every estimator is unbiased in frames off the map's axis, against a quadrature", "[geometry][unbiased]") {
  const std::vector<OffAxisCase> cases = offAxisCases();
  const double rhoD = 0.3, rhoS = 0.7, n = 20;
  const std::string grid = fmt::format("uniform:{},{},{}", rhoD, rhoS, n);
  BiasFamily family(0.02);
  uint64_t seed = 1000;
  for (const OffAxisCase& c : cases) {
    const PixelFrame frame = frameAt(c.normal, c.view);
    const std::string map = fmt::format("cosk:{}", c.K);
    Scene scene = smallScene(map, grid, 32, 32), split = smallScene(map, grid, 32, 32, true);
    for (Scene* s : {&scene, &split}) std::fill(s->geometry.pixels.begin(), s->geometry.pixels.end(), frame);
    const double expected = quadratureValue(c.K, rhoD, rhoS, n, frame);
    REQUIRE(expected > 0.01);
    addEveryEstimator(family, scene, split,
                      fmt::format("normal ({:.3f}, {:.3f}, {:.3f}) view {}° K {} (quadrature {:.6f})", c.normal[0],
                                  c.normal[1], c.normal[2], c.view, c.K, expected),
                      expected, seed);
  }
  checkFamily(family);
}

TEST_CASE("the optimal pdf per pixel is unbiased in frames off the map's axis, against a quadrature",
          "[geometry][unbiased][optimal]") {
  // Each pixel builds its table from its own normal and view.
  BiasFamily family(0.02);
  uint64_t seed = 3000;
  for (const OffAxisCase& c : offAxisCases()) {
    const Scene scene = pixelOptimalOffAxisScene(c, false);
    const double expected = quadratureValue(c.K, kRhoD, kRhoS, kN, frameAt(c.normal, c.view));
    for (Estimator e : {Estimator::MultiSample, Estimator::OneSample, Estimator::CountIndependent})
      addSized(family, fmt::format("{}: equal estimator {}", offAxisName(c), int(e)), expected, 64, 4, ++seed,
               [&](int spp, uint64_t sd) { return renderMean(scene, Method::Equal, e, spp, sd); });
  }
  checkFamily(family);
}

TEST_CASE("the optimal pdf per pixel is unbiased where quads of pixels share a table, against a quadrature",
          "[geometry][unbiased][optimal][pairs]") {
  // Pixel 2k + 1's normal is pixel 2k's turned by 1.5° and its exponent 3 % larger: each
  // quad samples the table of its mean inputs (kernels/pixel_pairs.h), which is neither
  // pixel's own. The image's mean is the mean of both frames' quadratures.
  BiasFamily family(0.02);
  uint64_t seed = 3200;
  for (const OffAxisCase& c : offAxisCases()) {
    Scene scene = pixelOptimalOffAxisScene(c, false);
    const Vec3d t = basisAbout(c.normal)[0];
    const Vec3d turned =
        unit({c.normal[0] + 0.026 * t[0], c.normal[1] + 0.026 * t[1], c.normal[2] + 0.026 * t[2]});
    const PixelFrame even = frameAt(c.normal, c.view), odd = frameAt(turned, c.view);
    for (int p = 1; p < scene.pixelCount(); p += 2) {
      scene.geometry.pixels[size_t(p)] = odd;
      scene.grid.pixels[size_t(p)].n = float(kN * 1.03);
    }
    const StagePlan plan = singleStagePlan(scene, Method::Equal, 64);
    // Pixels 0 … 3 alternate the two frames: the pairs alike, and their means the same.
    REQUIRE(scene.grid.width >= 4);
    std::vector<kern::PixelCdfInputs> quad;
    for (int p = 0; p < 4; ++p) quad.push_back(stageCdfInputs(scene, plan, p, 0).first);
    const int cells = scene.tables.pixelCells;
    const kern::PairTable low = kern::pairTableOf(quad[0], quad[1], 1, cells);
    REQUIRE(low.shares);
    REQUIRE(kern::quadGroup(0, 0, low, kern::pairTableOf(quad[2], quad[3], 1, cells), cells).size == 4);
    const double expected =
        0.5 * (quadratureValue(c.K, kRhoD, kRhoS, kN, even) + quadratureValue(c.K, kRhoD, kRhoS, kN * 1.03, odd));
    for (Estimator e : {Estimator::MultiSample, Estimator::OneSample})
      addSized(family, fmt::format("{}, quads: equal estimator {}", offAxisName(c), int(e)), expected, 64, 4, ++seed,
               [&](int spp, uint64_t sd) { return renderMean(scene, Method::Equal, e, spp, sd); });
  }
  checkFamily(family);
}

TEST_CASE("the product technique from the pixel's cells is unbiased in frames off the map's axis, against a quadrature",
          "[geometry][unbiased][product]") {
  // With the optimal pdf per pixel, each pixel's product is its own table over the cells
  // at C = 1, from its own normal and view (kernels/pixel_optimal.h): the product alone,
  // the three techniques at equal counts, one-sample MIS, and `exact`, which allocates
  // over the three and builds each stage's envmap table for the share it allocated.
  BiasFamily family(0.02);
  uint64_t seed = 3500;
  for (const OffAxisCase& c : offAxisCases()) {
    const Scene scene = pixelOptimalOffAxisScene(c, true);
    REQUIRE(scene.productTables.pixelCells);
    const double expected = quadratureValue(c.K, kRhoD, kRhoS, kN, frameAt(c.normal, c.view));
    const std::string where = offAxisName(c);
    addSized(family, where + ": the product alone", expected, 64, 4, ++seed, [&](int spp, uint64_t sd) {
      StagePlan plan = singleStagePlan(scene, Method::Equal, spp);
      for (int p = 0; p < scene.pixelCount(); ++p)
        plan.counts[3 * p] = plan.counts[3 * p + 1] = 0, plan.counts[3 * p + 2] = spp;
      return pixelMean(sweepSampler(scene, {Estimator::MultiSample, 0, 0})->run(plan, sd).rgb);
    });
    for (Estimator e : {Estimator::MultiSample, Estimator::OneSample})
      addSized(family, fmt::format("{}: equal estimator {}", where, int(e)), expected, 64, 4, ++seed,
               [&](int spp, uint64_t sd) { return renderMean(scene, Method::Equal, e, spp, sd); });
    addSized(family, where + ": exact", expected, 64, 64, ++seed, [&](int spp, uint64_t sd) {
      AdaptiveOptions options;
      options.costs.assign(3, 1.0);
      const auto sampler = sweepSampler(
          scene, samplerConfigFor(Method::Exact, Estimator::MultiSample, spp, options, scene.techniqueCount()));
      const Rendering r = render(*sampler, Method::Exact, options, spp, sd);
      return pixelMean(std::vector<double>(r.image.rgb.begin(), r.image.rgb.end()));
    });
  }
  checkFamily(family);
}

TEST_CASE("the optimal pdf and the product technique refuse per-pixel frames", "[geometry][safety]") {
  Scene scene = smallScene("cosk:1", "seed000", 8, 8);
  CHECK(scene.geometry.flat());
  giveRandomFrames(scene, 2);
  CHECK_FALSE(scene.geometry.flat());
  CHECK_THROWS_WITH(flatMirror(scene.geometry, "--product"),
                    Catch::Contains("--product with per-pixel normals or views: not implemented"));
}
