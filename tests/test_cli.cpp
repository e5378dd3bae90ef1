// The command line: bad input gets a clear message naming the problem, a non-zero
// exit, and no output file; a good run writes its image and report.
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>

#include "CliRunner.h"
#include "Error.h"
#include "RawExr.h"
#include "TestDevice.h"
#include "cl/Device.h"
#include "distributions/CompensatedPdf.h"
#include "scene/ExrIO.h"

namespace fs = std::filesystem;

using misalloc::test::runMisalloc;
using misalloc::test::TempDir;

TEST_CASE("render writes an image and a report", "[cli]") {
  TempDir dir;
  auto out = dir.path / "r.exr", report = dir.path / "r.json";
  auto r =
      runMisalloc(fmt::format("render --envmap cosk:1 --grid seed000 --size 16x8 --spp 8 --device cpu "
                              "--out {} --report {} --cache-dir {}",
                              out.string(), report.string(), (dir.path / "cache").string()));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  REQUIRE(fs::exists(out));
  nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  CHECK(j["method"] == "exact");
  CHECK(j["spp"] == 8);
  CHECK(j["reference"]["source"] == "analytic ([HS14] eq. 6.17)");
  CHECK(j["rmse_x1000"].get<double>() > 0);
  CHECK(j["time_s"]["kernel"].get<double>() > 0);
  CHECK(j["time_s"]["wall"].get<double>() >= j["time_s"]["kernel"].get<double>());
}

// [release-only]: the cost cache's host code runs sanitized in test_cost_model.cpp's cache tests.
TEST_CASE("the default render is repeatable: its costs are calibrated once and cached", "[cli][release-only]") {
  TempDir dir("repeatable");
  // The default method allocates by cost: without the cache, each run would allocate
  // with its own timings.
  auto render = [&](const std::string& extra) {
    const fs::path out = dir.path / "r.exr", report = dir.path / "r.json";
    auto r = runMisalloc(fmt::format(
        "render --envmap sun --size 32x32 --spp 64 --device cpu --no-preview --cache-dir {} --out {} --report {} {}",
        (dir.path / "cache").string(), out.string(), report.string(), extra));
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    std::ifstream image(out, std::ios::binary);
    return std::make_pair(std::string(std::istreambuf_iterator<char>(image), {}),
                          nlohmann::json::parse(std::ifstream(report)));
  };
  const auto [first, firstReport] = render("");
  CHECK(firstReport["allocation"]["costs_source"] == "calibrated");
  const auto [second, secondReport] = render("--cost cached");
  CHECK(secondReport["allocation"]["costs_source"] == "cache");
  CHECK(second == first);
  nlohmann::json cachedModel = firstReport["allocation"]["cost_model"];
  cachedModel["source"] = "cache";
  CHECK(secondReport["allocation"]["cost_model"] == cachedModel);
  const auto [measured, measuredReport] = render("--cost measure");
  CHECK(measuredReport["allocation"]["costs_source"] == "calibrated");
  CHECK(measuredReport["allocation"]["costs_s_per_sample"] != firstReport["allocation"]["costs_s_per_sample"]);
  const auto [after, afterReport] = render("");
  CHECK(after == measured);
  CHECK(afterReport["allocation"]["costs_s_per_sample"] == measuredReport["allocation"]["costs_s_per_sample"]);
}

namespace {

// A 16×16 render of `scene` with `args`: its image's bytes and its report.
std::pair<std::string, nlohmann::json> render16(const fs::path& dir, const std::string& scene,
                                                const std::string& args) {
  const fs::path out = dir / "r.exr", report = dir / "r.json";
  auto r = runMisalloc(
      fmt::format("render {} --size 16x16 --spp 100 --cost 1,1 --device cpu --reference none --no-preview --out {} "
                  "--report {} {}",
                  scene, out.string(), report.string(), args));
  INFO(args << "\n" << r.output);
  REQUIRE(r.exitCode == 0);
  std::ifstream image(out, std::ios::binary);
  return {std::string(std::istreambuf_iterator<char>(image), {}), nlohmann::json::parse(std::ifstream(report))};
}

// Where linear's weights go negative in places (the rules differ), and where exact's
// predicted gain varies from pixel to pixel.
const std::string kGlossy = "--envmap cosk:1 --grid uniform:0.5,0.5,20", kSun = "--envmap sun --grid seed000";

}  // namespace

TEST_CASE("render --linear-rule chooses how linear treats negative weights, and reaches the render",
          "[cli][adaptive]") {
  TempDir dir("linear_rule");
  const auto variance = render16(dir.path, kGlossy, "--method linear --linear-rule variance");
  const auto drop = render16(dir.path, kGlossy, "--method linear --linear-rule drop");
  CHECK(render16(dir.path, kGlossy, "--method linear").second["allocation"]["zero_weight_rule"] ==
        variance.second["allocation"]["zero_weight_rule"]);  // the default
  CHECK(variance.second["allocation"]["zero_weight_rule"] == "min sample variance ([SS23] eq. 19)");
  CHECK(drop.second["allocation"]["zero_weight_rule"] == "drop most negative ([SS23] Sec. 5.1)");
  CHECK(variance.first != drop.first);
  auto bad = runMisalloc("render --method linear --linear-rule both --size 4x4 --spp 8 --device cpu --out " +
                         (dir.path / "x.exr").string());
  CHECK(bad.exitCode == 2);
  CHECK(bad.output.find("--linear-rule 'both'") != std::string::npos);
  CHECK_FALSE(fs::exists(dir.path / "x.exr"));
}

// Release only: six renders of exact (13 s sanitized); the skip rule's host code runs
// sanitized in test_adaptive.cpp.
TEST_CASE("render --skip-below keeps equal counts in more pixels as it rises, and reaches the render",
          "[cli][adaptive][release-only]") {
  TempDir dir("skip_below");
  size_t before = 0;
  std::string defaultImage;
  for (const char* gain : {"0", "0.02", "0.3", "0.9"}) {
    const auto [image, report] = render16(dir.path, kSun, std::string("--method exact --skip-below ") + gain);
    INFO(gain);
    CHECK(report["allocation"]["skip_below"] == std::stod(gain));
    const size_t skipped = report["allocation"]["skipped_pixels"];
    CHECK(skipped >= before);
    before = skipped;
    if (std::string(gain) == "0.02") {
      CHECK(render16(dir.path, kSun, "--method exact").first == image);  // the default
      CHECK(skipped < 256);
      defaultImage = image;
    }
  }
  // No predicted gain reaches 90 %: every pixel keeps equal counts, another image.
  CHECK(before == 256);
  CHECK(render16(dir.path, kSun, "--method exact --skip-below 0.9").first != defaultImage);
}

TEST_CASE("render --scene spheres writes the background transparent black, and reports its pdf and coverage",
          "[cli][scenes]") {
  TempDir dir;
  auto out = dir.path / "s.exr", report = dir.path / "s.json";
  auto r =
      runMisalloc(fmt::format("render --scene spheres:2x2 --envmap cosk:1 --size 16x16 --spp 16 --device cpu "
                              "--reference none --out {} --report {}",
                              out.string(), report.string()));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  const misalloc::RgbImage image = misalloc::readExr(out.string());
  REQUIRE(image.alpha.size() == 256);
  size_t covered = 0, blackBackground = 0;
  for (size_t p = 0; p < 256; ++p) {
    covered += image.alpha[p] == 1;
    blackBackground +=
        image.alpha[p] == 0 && image.rgb[3 * p] == 0 && image.rgb[3 * p + 1] == 0 && image.rgb[3 * p + 2] == 0;
  }
  CHECK(covered > 100);
  CHECK(covered + blackBackground == 256);
  nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  CHECK(j["scene"]["shape"] == "spheres:2x2");
  CHECK(j["scene"]["covered_pixels"] == covered);
  CHECK(j["scene"]["view_deg"][0] == 75.0);
  CHECK(j["scene"]["envmap_pdf"]["used"] == "optimal-pixel");
  // The pilot's cells, coarser than the render's, as it asked.
  CHECK(j["scene"]["envmap_pdf"]["pilot_cells"]["across"] == misalloc::kDefaultPilotCellsAcross);
  CHECK(j["scene"]["envmap_pdf"]["pixel_cells"]["across"] == misalloc::kDefaultPixelCellsAcross);
}

TEST_CASE("bad options fail clearly and write nothing", "[cli][bad-input]") {
  TempDir dir;
  auto out = dir.path / "r.exr", report = dir.path / "r.json";
  const std::string outputs = fmt::format("--out {} --report {} --reference none", out.string(), report.string());
  struct Case {
    std::string args, expected;
  };
  const Case cases[] = {
      {"--envmap /no/such/file.exr", "/no/such/file.exr"},
      {"--envmap no_such_map", "no_such_map"},
      {"--spp 0", "--spp: '0'"},
      {"--size 0x0", "--size 0x0"},
      {"--size 12", "--size 12"},
      {"--method magic", "unknown --method 'magic'"},
      {"--method exact --spp 40 --grid-u 1", "--grid-u: '1'"},
      {"--method exact --spp 40 --grid-rule best", "--grid-rule 'best'"},
      {"--method heuristic --spp 4", "smaller than the pilot"},
      {"--method heuristic --spp 40 --cost 1,0", "costs must be positive"},
      {"--method heuristic --spp 40 --cost 1", "expected 2 numbers"},
      {"--method heuristic --pilot 1.5", "--pilot: '1.5'"},
      {"--method heuristic --estimator one", "multi-sample stages"},
      {"--method ris --estimator one", "an estimator of its own"},
      {"--method ris --envmap-pdf optimal", "--method ris with --envmap-pdf optimal"},
      {"--grid marble", "unknown --grid 'marble'"},
      {"--grid uniform:0.8,0.8,10", "ρd + ρs ≤ 1"},
      {"--device 99", "--device '99'"},
      {"--device quantum", "--device 'quantum'"},
      {"--estimator both", "--estimator 'both'"},
      {"--envmap-sampler tree", "--envmap-sampler 'tree'"},
      {"--view 95", "--view 95"},
      {"--envmap cosk:x", "cosk:x"},
      {"--scene cube", "unknown --scene 'cube'"},
      {"--scene spheres:0x2", "--scene spheres:0x2"},
      {"--scene sphere --view 200", "--view 200"},
      {"--scene sphere --envmap-pdf optimal", "--envmap-pdf optimal with per-pixel normals or views: not implemented"},
      {"--scene sphere --envmap-pdf optimal-pixel:16/32", "P, the pilot's cells across the map"},
      {"--scene sphere --product --envmap-pdf plain",
       "--product with --envmap-pdf plain and per-pixel normals or views: not implemented"},
      {"--product --method envmap", "--product with --method envmap: envmap samples the envmap alone"},
      {"--product --method brdf", "--product with --method brdf: brdf samples the BRDF alone"},
      {"--product --method ris --envmap-pdf plain", "--product with --method ris"},
  };
  for (const Case& c : cases) {
    auto r = runMisalloc(fmt::format("render --size 8x8 --spp 8 {} {}", outputs, c.args));
    INFO(c.args << "\n" << r.output);
    CHECK(r.exitCode != 0);
    CHECK(r.output.find(c.expected) != std::string::npos);
    CHECK_FALSE(fs::exists(out));
    CHECK_FALSE(fs::exists(report));
  }
}

TEST_CASE("bad envmap files fail clearly through the CLI and write nothing", "[cli][bad-input]") {
  TempDir dir;
  auto file = [&](const std::string& name) { return (dir.path / name).string(); };
  std::ofstream(file("garbage.exr")) << "#?RADIANCE\nnot an OpenEXR file\n";
  std::ofstream(file("empty.exr"));
  {
    std::ifstream in(MISALLOC_SOURCE_DIR "/data/envmaps/lebombo.exr", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(file("cut.exr"), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  misalloc::writeExrChannels(file("rg.exr"), 4, 2, {"R", "G"},
                             {std::vector<float>(8, 1.0f), std::vector<float>(8, 1.0f)});
  {
    // OpenEXR cannot write an empty data window: patch max.x of a good file's below min.x.
    misalloc::writeExr(file("good.exr"), misalloc::RgbImage{4, 2, std::vector<float>(24, 1.0f)});
    std::ifstream in(file("good.exr"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string attribute("dataWindow\0box2i\0", 17);
    size_t at = bytes.find(attribute);
    REQUIRE(at != std::string::npos);
    int32_t maxX = -1;
    std::memcpy(&bytes[at + attribute.size() + 4 + 8], &maxX, 4);  // after the size, min.x, min.y
    std::ofstream(file("zero.exr"), std::ios::binary) << bytes;
  }
  misalloc::RgbImage nan{4, 2, std::vector<float>(24, 1.0f)};
  nan.rgb[3 * (1 * 4 + 2) + 0] = std::numeric_limits<float>::quiet_NaN();  // x=2, y=1, R
  misalloc::test::writeRawExr(file("nan.exr"), nan);
  REQUIRE(::mkfifo(file("fifo.exr").c_str(), 0600) == 0);  // would block an open() forever
  fs::create_directories(file("folder.exr"));
  struct Case {
    std::string name, expected;
  };
  const Case cases[] = {{"absent.exr", "no such file"},
                        {"garbage.exr", "not an OpenEXR file"},
                        {"empty.exr", "not an OpenEXR file"},
                        {"cut.exr", "truncated or corrupt"},
                        {"rg.exr", "no B channel"},
                        {"zero.exr", "data window"},
                        {"nan.exr", "1 NaN or infinite channel values, the first at x=2, y=1, channel R"},
                        {"fifo.exr", "is not a regular file"},
                        {"folder.exr", "is not a regular file"}};
  auto out = dir.path / "r.exr", report = dir.path / "r.json";
  for (const Case& c : cases) {
    // A run that blocks is killed: exit 124, not the 2 expected.
    auto r = runMisalloc(fmt::format("render --envmap {} --size 8x8 --spp 8 --reference none --out {} --report {}",
                                     file(c.name), out.string(), report.string()),
                         "timeout 60");
    INFO(c.name << "\n" << r.output);
    CHECK(r.exitCode == 2);
    CHECK(r.output.find(file(c.name)) != std::string::npos);
    CHECK(r.output.find(c.expected) != std::string::npos);
    CHECK_FALSE(fs::exists(out));
    CHECK_FALSE(fs::exists(report));
  }
}

TEST_CASE("negative texels are set to 0 with a warning and a count", "[cli][bad-input]") {
  TempDir dir;
  misalloc::RgbImage image{4, 2, std::vector<float>(24, 1.0f)};
  image.rgb[3 * 1 + 2] = -2.0f;  // x=1, y=0, B
  image.rgb[3 * 6 + 0] = -1.0f;
  const std::string map = (dir.path / "neg.exr").string();
  misalloc::writeExr(map, image);
  auto report = dir.path / "r.json";
  auto r = runMisalloc(fmt::format("render --envmap {} --size 8x8 --spp 8 --reference none --out {} --report {}", map,
                                   (dir.path / "r.exr").string(), report.string()));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  CHECK(r.output.find("2 negative values set to 0 (first at x=1, y=0, channel B)") != std::string::npos);
  nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  CHECK(j["scene"]["envmap_negative_values_zeroed"] == 2);
}

TEST_CASE("an existing output survives a failed run", "[cli][bad-input]") {
  TempDir dir;
  auto out = dir.path / "r.exr";
  std::ofstream(out) << "previous";
  auto r =
      runMisalloc(fmt::format("render --spp 0 --out {} --report {}", out.string(), (dir.path / "r.json").string()));
  CHECK(r.exitCode != 0);
  std::ifstream in(out);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(content == "previous");
}

TEST_CASE("no OpenCL platform: the message says how to install PoCL", "[cli][bad-input]") {
  // An empty vendor folder hides every ICD from the loader.
  TempDir dir;
  auto r = runMisalloc("devices",
                       fmt::format("OCL_ICD_VENDORS={} OPENCL_VENDOR_PATH={}", dir.path.string(), dir.path.string()));
  INFO(r.output);
  CHECK(r.exitCode != 0);
  CHECK(r.output.find("pocl-opencl-icd") != std::string::npos);
}

TEST_CASE("a kernel build failure shows the build log", "[cli][bad-input]") {
  using namespace misalloc;
  // A missing -D makes sample.cl fail to compile.
  try {
    buildProgram(test::testDevice(), "sample.cl", "-cl-std=CL1.2");
    FAIL("the build should have failed");
  } catch (const DeviceError& e) {
    std::string what = e.what();
    CHECK(what.find("Build log") != std::string::npos);
    CHECK(what.find("MA_TECHNIQUES") != std::string::npos);
  }
}
