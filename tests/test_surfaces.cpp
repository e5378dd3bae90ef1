// Surfaces (scene/Surfaces.h): which pixels pool their statistics. The labels follow
// coverage, normals and BRDFs; an allocation pooled over a window never reads another
// surface's pixels, so that a pixel beside a second material renders as if that
// material were not there.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <set>

#include "SceneFixtures.h"
#include "TestDevice.h"
#include "render/Render.h"
#include "scene/Surfaces.h"

using namespace misalloc;
using namespace misalloc::test;

TEST_CASE("surfaces: a smooth grid is one, a jump in normal or BRDF or the background cuts", "[surfaces]") {
  // seed000 at 16 pixels: the steepest gradient the labels must keep whole.
  Scene plane = smallScene("cosk:1", "seed000", 16, 16);
  CHECK(std::set<int32_t>(plane.surfaces.begin(), plane.surfaces.end()) == std::set<int32_t>{0});

  SceneOptions options = smallSceneOptions("cosk:1", "seed000", 64, 64);
  options.shape = "spheres:2x2";
  options.envmapPdf = parseEnvmapPdf("plain");
  const Scene spheres = makeScene(options);
  std::set<int32_t> labels;
  int misplaced = 0;
  for (size_t p = 0; p < spheres.surfaces.size(); ++p) {
    misplaced += (spheres.surfaces[p] < 0) != !spheres.geometry.covered[p];
    labels.insert(spheres.surfaces[p]);
  }
  CHECK(misplaced == 0);
  CHECK(labels == std::set<int32_t>{-1, 0, 1, 2, 3});  // the background and one per sphere

  // A material that changes across the middle, then a normal that turns there.
  Scene halves = smallScene("cosk:1", "uniform:0.5,0.5,20", 8, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 4; x < 8; ++x) halves.grid.pixels[size_t(y * 8 + x)] = PhongParameters{0.5f, 0.5f, 50};
  halves.surfaces = labelSurfaces(halves.geometry, halves.grid);
  CHECK(halves.surfaces[3] == 0);
  CHECK(halves.surfaces[4] == 1);
  for (int y = 0; y < 4; ++y)
    for (int x = 4; x < 8; ++x) {
      halves.grid.pixels[size_t(y * 8 + x)] = halves.grid.pixels[0];
      halves.geometry.pixels[size_t(y * 8 + x)].normal = Vec3f{0.6f, 0.0f, 0.8f};  // 37° from z
    }
  halves.surfaces = labelSurfaces(halves.geometry, halves.grid);
  CHECK(halves.surfaces[3] != halves.surfaces[4]);
}

TEST_CASE("a pooled allocation beside another surface is the allocation without it, bit for bit", "[surfaces]") {
  // The left half glossy, the right half either a diffuse material or background: the
  // left half's pixels (the random numbers are each pixel's own) must render the same.
  const int width = 24, height = 16;
  Scene beside = smallScene("sun", "uniform:0.2,0.8,200", width, height);
  Scene alone = beside;
  for (int y = 0; y < height; ++y)
    for (int x = width / 2; x < width; ++x) {
      beside.grid.pixels[size_t(y * width + x)] = PhongParameters{0.9f, 0.1f, 1};
      alone.geometry.covered[size_t(y * width + x)] = 0;
    }
  beside.surfaces = labelSurfaces(beside.geometry, beside.grid);
  alone.surfaces = labelSurfaces(alone.geometry, alone.grid);
  for (Method method : {Method::Exact, Method::Heuristic}) {
    INFO(methodName(method));
    AdaptiveOptions options;
    options.costs = {1.0, 1.5};
    options.stages = 2;
    const int spp = 48;
    Sampler onBeside(testDevice(), beside,
                     samplerConfigFor(method, Estimator::MultiSample, spp, options, beside.techniqueCount()));
    Sampler onAlone(testDevice(), alone,
                    samplerConfigFor(method, Estimator::MultiSample, spp, options, alone.techniqueCount()));
    const Rendering a = render(onBeside, method, options, spp, 3), b = render(onAlone, method, options, spp, 3);
    int differ = 0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width / 2; ++x) {
        const size_t p = size_t(y * width + x);
        for (int c = 0; c < 3; ++c) differ += a.image.rgb[3 * p + c] != b.image.rgb[3 * p + c];
        for (int k = 0; k < 2; ++k) differ += a.alpha[2 * p + k] != b.alpha[2 * p + k];
      }
    CHECK(differ == 0);
  }
}
