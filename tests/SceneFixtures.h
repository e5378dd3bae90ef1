#pragma once
// Small scenes and per-pixel statistics shared by the sampler tests.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "Constants.h"
#include "KernelCode.h"
#include "TestDevice.h"
#include "TestSize.h"
#include "render/Method.h"
#include "sampling/HostSampler.h"
#include "sampling/KernelViews.h"
#include "sampling/Sampler.h"
#include "scene/Scene.h"
#include "scene/Surfaces.h"

namespace misalloc::test {

// A small scene's options: a procedural map of 128 texels across.
inline SceneOptions smallSceneOptions(const std::string& envmap, const std::string& grid, int w, int h) {
  SceneOptions o;
  o.envmap = envmap;
  o.grid = grid;
  o.width = w;
  o.height = h;
  o.proceduralWidth = 128;
  return o;
}

inline Scene smallScene(const std::string& envmap, const std::string& grid, int w, int h, bool split = false,
                        EnvmapSampler sampler = EnvmapSampler::Alias, double viewTheta = 0,
                        const std::string& envmapPdf = "plain", bool product = false) {
  SceneOptions o = smallSceneOptions(envmap, grid, w, h);
  o.envmapPdf = parseEnvmapPdf(envmapPdf);
  o.splitBrdf = split;
  o.product = product;
  o.sampler = sampler;
  o.viewTheta = viewTheta;
  return makeScene(o);
}

// A unit direction drawn uniformly on the sphere from Philox stream `key`, draw `index`.
inline Vec3f randomDirection(uint32_t key, uint32_t index) {
  const kern::MaRandom4 r = kern::philoxDraw(0x6e0, 0, key, 7u, index);
  const double z = 1 - 2 * (double(r.v[0]) + 0.5) / 4294967296.0, phi = 2 * kPi * double(r.v[1]) / 4294967296.0;
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {float(s * std::cos(phi)), float(s * std::sin(phi)), float(z)};
}

// A frame with normal `normal` seen from ω_o = `view` (unit vectors, n·ω_o > 0).
inline PixelFrame frameSeenFrom(const Vec3f& normal, const Vec3f& view) {
  return {normal, mirrorDirection(normal, view)};
}

// Every pixel of `scene` in a frame of its own: a normal anywhere on the sphere (facing
// the map's ground too) and a view in its upper hemisphere, at least 3° above its horizon.
inline void giveRandomFrames(Scene& scene, uint32_t key) {
  for (int p = 0; p < scene.pixelCount(); ++p) {
    const Vec3f n = randomDirection(key, uint32_t(2 * p));
    Vec3f v = randomDirection(key, uint32_t(2 * p + 1));
    double d = double(n[0]) * v[0] + double(n[1]) * v[1] + double(n[2]) * v[2];
    if (d < 0) v = {-v[0], -v[1], -v[2]}, d = -d;
    if (d < 0.05) {  // lifted off the horizon: ω_o + (0.05 − n·ω_o) n, normalised
      Vec3f lifted;
      double len = 0;
      for (int c = 0; c < 3; ++c) lifted[c] = float(v[c] + (0.05 - d) * n[c]), len += double(lifted[c]) * lifted[c];
      for (int c = 0; c < 3; ++c) lifted[c] = float(lifted[c] / std::sqrt(len));
      v = lifted;
    }
    scene.geometry.pixels[size_t(p)] = frameSeenFrom(n, v);
  }
  scene.surfaces = labelSurfaces(scene.geometry, scene.grid);
}

// Every `period`-th pixel, from pixel 1, made background (SceneGeometry::covered).
inline void giveBackground(Scene& scene, int period) {
  for (size_t p = 1; p < scene.geometry.covered.size(); p += size_t(period)) scene.geometry.covered[p] = 0;
  scene.surfaces = labelSurfaces(scene.geometry, scene.grid);
}

// Pixel `pixel`'s table inputs in `plan`'s stage of the multi-sample estimator
// (kernels/pixel_pairs.h), and whether it takes samples there.
inline std::pair<kern::PixelCdfInputs, bool> stageCdfInputs(const Scene& scene, const StagePlan& plan, int pixel,
                                                            int product) {
  const kern::StageCounts c = kern::loadStageCounts(plan.counts.data(), plan.firstIndex.data(), pixel,
                                                    plan.techniqueCount, plan.stageSamples, 0, 0, 1);
  const kern::ShadingPoint sp = makeShadingPoint(scene, pixel);
  return {kern::cdfInputsOf(sp.brdf, sp.normalFrame.z, sp.mirrorFrame.z, c, product), kern::pixelStageSamples(c) > 0};
}

// The sampler of the statistical sweeps: the C++ reference, which computes the kernel's
// floats bit for bit on every path the sweeps take (tests/test_sampler.cpp), so that a
// sweep tests the estimator and not PoCL, and compiles no kernel per scene. With
// MISALLOC_TEST_SIZE=exhaustive, the kernel on PoCL.
inline std::unique_ptr<StageSampler> sweepSampler(const Scene& scene, const SamplerConfig& config) {
  if (exhaustiveTestSize()) return std::make_unique<Sampler>(testDevice(), scene, config);
  return std::make_unique<HostSampler>(scene, config);
}

// Mean and standard error of the pixels' luminance estimates, for scenes whose
// pixels all have the same expected value (a uniform grid): independent estimates.
struct MeanAndError {
  double mean, standardError;
};

inline MeanAndError pixelMean(const std::vector<double>& rgb) {
  const size_t n = rgb.size() / 3;
  double sum = 0, sumSquares = 0;
  for (size_t p = 0; p < n; ++p) {
    double y = luminance(rgb[3 * p], rgb[3 * p + 1], rgb[3 * p + 2]);
    sum += y;
    sumSquares += y * y;
  }
  double mean = sum / n;
  double variance = (sumSquares - n * mean * mean) / (n - 1);
  return {mean, std::sqrt(std::max(variance, 0.0) / n)};
}

// A zero-variance estimator (f ∝ p) still carries float rounding: each sample's
// f/(N p) is a float, ~1e-7 relative. The error it is measured against has that floor.
inline double zScore(double mean, double expected, double standardError) {
  return (mean - expected) / std::max(standardError, 1e-6 * std::abs(expected));
}

// [HS14] eq. 6.17: the pixel value under R = cos^K θ with ω_o along the normal, R = 1.
inline double closedForm(double rhoD, double rhoS, double n, double K) {
  return 2 * rhoD / (K + 2) + rhoS * (n + 2) / (n + K + 2);
}

// Values of a and b that differ bit for bit, a length's difference counted as that many:
// a kernel against its C++ reference.
template <typename T>
size_t differingValues(const std::vector<T>& a, const std::vector<T>& b) {
  size_t differ = std::max(a.size(), b.size()) - std::min(a.size(), b.size());
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) differ += a[i] != b[i];
  return differ;
}

// A stage's sums that differ between two samplers: the image's and the techniques' moments.
inline size_t stageMismatches(const StageResult& a, const StageResult& b) {
  return differingValues(a.rgb, b.rgb) + differingValues(a.moments, b.moments);
}

}  // namespace misalloc::test
