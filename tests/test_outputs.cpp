// What a render's pictures show, decoded: its preview is its EXR tone-mapped as
// report/PreviewPng.h says, and its α map holds the allocation its report states and
// draws it as report/AlphaMap.h says. compare's pictures: tests/test_compare.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "CliRunner.h"
#include "PictureChecks.h"
#include "report/AlphaMap.h"
#include "report/PreviewPng.h"
#include "scene/ExrIO.h"

using namespace misalloc;
using namespace misalloc::test;
namespace fs = std::filesystem;

TEST_CASE("a render's preview and alpha map show its image and the allocation its report states", "[cli][outputs]") {
  TempDir dir("outputs");
  const fs::path exr = dir.path / "r.exr", alphaMap = dir.path / "a.exr", report = dir.path / "r.json";
  const int width = 24, height = 16;
  // A sphere leaves a background. Without a reference the preview's exposure is the
  // image's own. Given costs: calibrated ones move the shares with the machine's load,
  // and under the sanitizers they once made them nearly equal.
  const auto r = runMisalloc(fmt::format(
      "render --scene sphere --envmap cosk:2 --size {}x{} --spp 16 --method heuristic --cost 1,1 --reference none "
      "--device cpu --out {} --alpha-map {} --report {} --cache-dir {}",
      width, height, exr.string(), alphaMap.string(), report.string(), (dir.path / "cache").string()));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  const RgbImage image = readExr(exr.string());
  REQUIRE(image.width == width);
  REQUIRE(image.height == height);
  REQUIRE(image.alpha.size() == size_t(width) * height);
  CHECK(image.coveredPixels() > 0);
  CHECK(image.coveredPixels() < image.alpha.size());

  const Picture preview = readPng(previewPath(exr.string()));
  CHECK(preview.width == width);
  CHECK(preview.height == height);
  CHECK(previewMismatches(preview, image, previewExposure(image)) == 0);
  // Mid-tones, where a wrong curve or channel order shows.
  CHECK(std::count_if(preview.rgb.begin(), preview.rgb.end(), [](uint8_t b) { return b > 16 && b < 240; }) > 50);

  const nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  const auto techniques = j["scene"]["techniques"].get<std::vector<std::string>>();
  REQUIRE(techniques.size() == 2);
  REQUIRE(techniques.front() == "envmap");
  const auto planes = readAlphaMap(alphaMap.string(), techniques, width, height);
  const AlphaSummary alpha = summarizeAlpha(planes, image);
  CHECK(alpha.offSimplex == 0);
  for (size_t k = 0; k < techniques.size(); ++k) {
    INFO(techniques[k]);
    CHECK(alpha.coveredMean[k] == Approx(j["mean_alpha"][techniques[k]].get<double>()).margin(1e-6));
  }
  // Unequal shares, so that a plane given the other's name shows.
  CHECK(std::abs(alpha.coveredMean[0] - alpha.coveredMean[1]) > 0.05);

  const Picture picture = readPng(alphaPngPath(alphaMap.string()));
  CHECK(picture.width == width);
  CHECK(picture.height == height);
  CHECK(alphaPictureMismatches(picture, planes.front(), image) == 0);
}
