// A sharded render: bands of whole 16-pixel-block rows merged into the unsharded
// image bit for bit, for every method (exact's pooling over several stages included),
// and merge's refusals of bands that do not make one run's image.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "CliRunner.h"
#include "SafetyWorkspace.h"
#include "TestSize.h"
#include "render/Band.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

// A 16×40 image: three bands of 16, 16 and 8 rows; given costs, the same on every node.
// exact's whole-image rule off, in the bands and the unsharded render alike: it decides
// from the whole image, and a band refuses it (the refusals below).
std::string renderArgs(const fs::path& dir, const std::string& method, const std::string& extra) {
  return fmt::format(
      "render --envmap sun --size 16x40 --spp 48 --method {}{} --cost 1,1.5 --device cpu --reference none "
      "--no-preview --report {} {}",
      method, method == "exact" ? " --skip-image-below 0" : "", (dir / "report.json").string(), extra);
}

std::string bandPath(const fs::path& dir, int k) { return (dir / fmt::format("band{}.exr", k)).string(); }

// `merge` of `bands` into dir/`stem`.exr, its report dir/`stem`.json.
std::string mergeArgs(const fs::path& dir, const std::string& stem, const std::vector<std::string>& bands) {
  return fmt::format("merge --out {} --report {} {}", (dir / (stem + ".exr")).string(),
                     (dir / (stem + ".json")).string(), fmt::join(bands, " "));
}

// Renders bands `ks` of `bands` of `method` with `extra`, each in a process of its own.
void renderBands(const fs::path& dir, const std::string& method, const std::string& extra, int bands,
                 const std::vector<int>& ks) {
  for (int k : ks) {
    auto r = runMisalloc(
        renderArgs(dir, method, fmt::format("{} --shard {}/{} --out {}", extra, k, bands, bandPath(dir, k))));
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
  }
}

}  // namespace

TEST_CASE("bands of whole block rows, their halo, and the shard option", "[band]") {
  Band b = bandOf({1, 3}, 40, 4);
  CHECK((b.rows.begin == 16 && b.rows.end == 32 && b.rendered.begin == 12 && b.rendered.end == 36));
  b = bandOf({2, 3}, 40, 4);
  CHECK((b.rows.begin == 32 && b.rows.end == 40 && b.rendered.begin == 28 && b.rendered.end == 40));
  CHECK_THROWS_AS(bandOf({3, 4}, 40, 0), InputError);  // three block rows for four bands
  CHECK(parseShard("2/5", "--shard").index == 2);
  for (const char* bad : {"5/5", "-1/2", "1", "a/2", "1/0", "1/2/3", ""})
    CHECK_THROWS_AS(parseShard(bad, "--shard"), InputError);
}

TEST_CASE("merged bands are the unsharded render bit for bit, for every method", "[band][cli]") {
  TempDir dir("band");
  // One of each kind of allocation a band computes: none, a per-pixel rule, the oracle,
  // the grid search alone (on a G-buffer of spheres, whose bands hold background) and pooled over a
  // halo of stages, the optimal weights' pilot (the other rules and fixed counts take
  // the same paths: the whole set with MISALLOC_TEST_SIZE=exhaustive).
  std::vector<std::string> variants{"equal",
                                    "heuristic",
                                    "oracle",
                                    "exact --gbuffer " + (dir.path / "spheres.exr").string(),
                                    "exact --stages 3 --pool 3",
                                    "exact --stages 3 --pool 3 --weights optimal"};
  if (exhaustiveTestSize())
    variants = {"equal",
                "envmap",
                "brdf",
                "heuristic",
                "sigma-sqrt-c",
                "linear",
                "oracle",
                "exact",
                "exact --stages 3 --pool 3",
                "equal --weights optimal",
                "exact --stages 3 --pool 3 --weights optimal"};
  // Under the sanitizers: a fixed split, the widest halo and the optimal weights' pooled
  // pilot, the same code paths.
  if (smallTestSize()) variants = {"equal", "exact --stages 3 --pool 3", "equal --weights optimal"};
  const auto spheres = runMisalloc(
      fmt::format("gbuffer --scene spheres:2x4 --size 16x40 --out {}", (dir.path / "spheres.exr").string()));
  REQUIRE(spheres.exitCode == 0);
  for (const std::string& variant : variants) {
    const std::string method = variant.substr(0, variant.find(' '));
    const std::string extra = variant.size() > method.size() ? variant.substr(method.size()) : "";
    INFO(variant);
    auto whole = runMisalloc(renderArgs(dir.path, method, extra + " --out " + (dir.path / "whole.exr").string()));
    INFO(whole.output);
    REQUIRE(whole.exitCode == 0);
    renderBands(dir.path, method, extra, 3, {0, 1, 2});
    auto merged = runMisalloc(
        mergeArgs(dir.path, "merged", {bandPath(dir.path, 2), bandPath(dir.path, 0), bandPath(dir.path, 1)}));
    INFO(merged.output);
    REQUIRE(merged.exitCode == 0);
    CHECK(readText(dir.path / "merged.exr") == readText(dir.path / "whole.exr"));
    const std::string report = readText(dir.path / "merged.json");
    CHECK(report.find("\"node\"") != std::string::npos);
    if (method != "equal" && method != "envmap" && method != "brdf")  // the allocating methods' costs
      CHECK(report.find("\"costs_source\": \"--cost\"") != std::string::npos);
  }
}

TEST_CASE("bands of an odd width merge bit for bit where pairs of pixels share a table", "[band][cli][pairs]") {
  // A uniform plane with the optimal pdf per pixel: every quad of a row shares a table
  // (kernels/pixel_pairs.h). 15 pixels wide with a halo of one row, the bands start on
  // odd pixels: quads taken by index instead of by their place in the row differ
  // there, and the halo's pilot reaches the band's first row through the pooling.
  TempDir dir("band-pairs");
  const std::string scene =
      "--scene plane --grid uniform:0.3,0.6,50 --envmap-pdf optimal-pixel --size 15x40 --method heuristic --pool 1";
  auto args = [&](const std::string& extra) {
    return fmt::format("render --envmap sun --spp 48 {} --cost 1,1.5 --device cpu --reference none --no-preview "
                       "--report {} {}",
                       scene, (dir.path / "report.json").string(), extra);
  };
  auto whole = runMisalloc(args("--out " + (dir.path / "whole.exr").string()));
  INFO(whole.output);
  REQUIRE(whole.exitCode == 0);
  for (int k = 0; k < 3; ++k) {
    auto r = runMisalloc(args(fmt::format("--shard {}/3 --out {}", k, bandPath(dir.path, k))));
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
  }
  auto merged =
      runMisalloc(mergeArgs(dir.path, "merged", {bandPath(dir.path, 0), bandPath(dir.path, 1), bandPath(dir.path, 2)}));
  INFO(merged.output);
  REQUIRE(merged.exitCode == 0);
  CHECK(readText(dir.path / "merged.exr") == readText(dir.path / "whole.exr"));
}

TEST_CASE("a band leaves the optimal pdf's cached tables to the whole image", "[band][cli][bankcache]") {
  TempDir dir("band_cache");
  const std::string cold = "--cache-dir " + (dir.path / "cache").string();
  renderBands(dir.path, "exact", cold, 3, {1});
  // A band's tables cover its own rows: cached under the image's key, they would
  // give the whole image's pixels the wrong bins (and read past their end).
  for (const char* cache : {"cache", "cache", "fresh"}) {
    auto whole = runMisalloc(renderArgs(dir.path, "exact",
                                        fmt::format("--cache-dir {} --out {}", (dir.path / cache).string(),
                                                    (dir.path / (std::string(cache) + ".exr")).string())));
    INFO(whole.output);
    REQUIRE(whole.exitCode == 0);
  }
  CHECK(readText(dir.path / "cache.exr") == readText(dir.path / "fresh.exr"));
}

TEST_CASE("merge refuses bands that do not make one run's image, and writes nothing", "[band][cli][safety]") {
  TempDir dir("band_refusals");
  renderBands(dir.path, "exact", "", 3, {0, 1, 2});
  const std::string other = (dir.path / "other").string();
  fs::create_directories(other);
  fs::create_directories(dir.path / "sub");
  renderBands(other, "exact", "--seed 2", 3, {2});     // another run
  renderBands(dir.path / "sub", "exact", "", 2, {1});  // another split of the same run
  const std::string b0 = bandPath(dir.path, 0), b1 = bandPath(dir.path, 1), b2 = bandPath(dir.path, 2);
  writeExr((dir.path / "plain.exr").string(), RgbImage{16, 8, std::vector<float>(16 * 8 * 3, 1.0f)});
  const std::string merge = mergeArgs(dir.path, "m", {});
  checkRefusals(
      dir.path,
      {{merge + b0 + " " + b1 + " " + bandPath(other, 2), "bands of different runs"},
       {merge + b0 + " " + b1, "rows 32 to 40 are missing"},
       {merge + b0 + " " + b2, "is missing"},
       {merge + b0 + " " + b1 + " " + b1 + " " + b2, "are the same band"},
       {merge + b0 + " " + b1 + " " + b2 + " " + bandPath(dir.path / "sub", 1), "different images or shard counts"},
       {merge + b0 + " " + b1 + " " + (dir.path / "plain.exr").string(), "not a band of a sharded render"},
       {merge + b0 + " " + b1 + " " + b2 + " --out " + b1, "--out"},
       {renderArgs(dir.path, "exact", "--shard 3/3 --out x.exr"), "--shard '3/3'"},
       // The whole-image rule on (the default): each band would decide from its own rows.
       {fmt::format("render --envmap sun --size 16x40 --spp 48 --device cpu --reference none --no-preview "
                    "--shard 0/3 --out {}",
                    (dir.path / "x.exr").string()),
        "whole-image rule"},
       {renderArgs(dir.path, "equal", "--shard 0/4 --out x.exr"), "fewer than the 4 bands"}},
      dir.path / "m.exr");
}

// [release-only]: the cost cache's host code runs sanitized in test_cost_model.cpp's cache tests,
// a band's identity with its costs in the sanitized merges of bands above.
TEST_CASE("bands without --cost allocate with the cost cache's one calibration", "[band][cli][release-only]") {
  TempDir dir("band_costs");
  // A band's sampler renders its rows, and takes the cached calibration of the whole
  // image's: the first band calibrates, the others and the whole render read it.
  auto render = [&](const std::string& cache, const std::string& extra, const std::string& out) {
    auto r = runMisalloc(fmt::format(
        "render --envmap sun --size 16x40 --spp 48 --method exact --skip-image-below 0 --device cpu --reference none "
        "--no-preview --cache-dir {} --report {} --out {} {}",
        (dir.path / cache).string(), (dir.path / "report.json").string(), (dir.path / out).string(), extra));
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
  };
  for (int k : {2, 0, 1}) render("cache", fmt::format("--shard {}/3", k), fmt::format("band{}.exr", k));
  render("cache", "", "whole.exr");
  CHECK(readText(dir.path / "report.json").find("\"costs_source\": \"cache\"") != std::string::npos);
  auto merged =
      runMisalloc(mergeArgs(dir.path, "merged", {bandPath(dir.path, 0), bandPath(dir.path, 1), bandPath(dir.path, 2)}));
  INFO(merged.output);
  REQUIRE(merged.exitCode == 0);
  CHECK(readText(dir.path / "merged.exr") == readText(dir.path / "whole.exr"));
  // A band calibrated apart (a node with a cache of its own) allocated with other costs.
  render("elsewhere", "--shard 1/3", "apart.exr");
  checkRefusals(
      dir.path,
      {{mergeArgs(dir.path, "m", {bandPath(dir.path, 0), (dir.path / "apart.exr").string(), bandPath(dir.path, 2)}),
        "costs"}},
      dir.path / "m.exr");
}

namespace {

// Renders band `k` of 3 of the 16×40 image of `scene`, from `folder`, into dir/`name`:
// relative input paths read that folder's files.
void renderBandIn(const fs::path& dir, const std::string& folder, const std::string& scene, int k,
                  const std::string& name) {
  auto r = runMisalloc(
      fmt::format("render {} --size 16x40 --spp 8 --method equal --device cpu --reference none --no-preview --report "
                  "r.json --shard {}/3 --out {}",
                  scene, k, (dir / name).string()),
      fmt::format("cd {} &&", (dir / folder).string()));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
}

}  // namespace

// Release only: 19 renders (20 s sanitized); the identity's code runs sanitized in
// test_compare_shard.cpp ("merge takes shards that spell the run's options differently").
TEST_CASE("merge compares the bands' inputs by content and their options by final value, not by spelling",
          "[band][cli][safety][release-only]") {
  TempDir dir("band_identity");
  // One name in three folders: `a` and `same` hold the same files, `other` other ones.
  const std::string quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n";
  for (const char* folder : {"a", "same", "other"}) {
    const fs::path f = dir.path / folder;
    fs::create_directories(f);
    const float radiance = folder == std::string("other") ? 0.75f : 0.5f;
    writeExr((f / "map.exr").string(), RgbImage{8, 4, std::vector<float>(96, radiance)});
    writeText(f / "mesh.obj", folder == std::string("other") ? "v -1 -1 0.5\n" + quad.substr(10) : quad);
    auto g =
        runMisalloc(fmt::format("gbuffer --scene {} --size 16x40 --out {}",
                                folder == std::string("other") ? "sphere" : "spheres:2x2", (f / "g.exr").string()));
    INFO(g.output);
    REQUIRE(g.exitCode == 0);
  }
  const std::string merge = mergeArgs(dir.path, "m", {});
  auto merged = [&](const std::string& prefix, const std::string& last) {
    return merge + fmt::format("{0}/{1}0.exr {0}/{1}1.exr {0}/{2}", dir.path.string(), prefix, last);
  };
  // The run's defaults spelled out, and the same map read from another folder: one run.
  renderBandIn(dir.path, "a", "--envmap map.exr", 0, "map0.exr");
  renderBandIn(dir.path, "a",
               "--envmap map.exr --seed 1 --estimator multi --weights balance --envmap-pdf optimal --view 0 "
               "--size 016x40",
               1, "map1.exr");
  renderBandIn(dir.path, "same", "--envmap map.exr", 2, "map2.exr");
  auto m = runMisalloc(merged("map", "map2.exr"));
  INFO(m.output);
  CHECK(m.exitCode == 0);
  fs::remove(dir.path / "m.exr");
  fs::remove(dir.path / "m.json");
  // A map, G-buffer or mesh of the same name with other contents: another run.
  renderBandIn(dir.path, "other", "--envmap map.exr", 2, "other_map2.exr");
  for (const char* input : {"gbuffer", "mesh"}) {
    const std::string scene = input == std::string("gbuffer") ? "--envmap sun --gbuffer g.exr"
                                                              : "--envmap sun --mesh mesh.obj --camera-origin 0,0,3";
    renderBandIn(dir.path, "a", scene, 0, fmt::format("{}0.exr", input));
    // A text option's numbers in another spelling: the same run.
    const std::string respelled = input == std::string("gbuffer") ? scene : scene + ".0 --camera-target 0e0,0,0";
    renderBandIn(dir.path, "a", respelled, 1, fmt::format("{}1.exr", input));
    renderBandIn(dir.path, "same", scene, 2, fmt::format("{}2.exr", input));
    renderBandIn(dir.path, "other", scene, 2, fmt::format("other_{}2.exr", input));
    m = runMisalloc(merged(input, fmt::format("{}2.exr", input)));
    INFO(m.output);
    CHECK(m.exitCode == 0);
    fs::remove(dir.path / "m.exr");
    fs::remove(dir.path / "m.json");
  }
  checkRefusals(dir.path,
                {{merged("map", "other_map2.exr"), "envmap texels"},
                 {merged("gbuffer", "other_gbuffer2.exr"), "gbuffer bytes"},
                 {merged("mesh", "other_mesh2.exr"), "mesh bytes"}},
                dir.path / "m.exr");
}
