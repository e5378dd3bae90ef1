// A sharded comparison: shards of whole scenes, or of (scene, repeat) pairs, merged into
// the unsharded run's folder, its images bit for bit and its errors to the digit (times
// excluded), and merge's refusals of folders that do not make one run.
#include <fmt/format.h>
#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "CliRunner.h"
#include "SafetyWorkspace.h"

using namespace misalloc::test;

namespace {

// The sweeps: the suite's scenes once each, or one scene three times.
const std::string kSuite = "--suite --repeats 1", kRepeats = "--envmap sun --repeats 3";

std::string compareArgs(const fs::path& dir, const std::string& sweep, const std::string& extra) {
  return fmt::format(
      "compare {} --size 8x8 --methods equal,exact --envmap-pdfs plain,compensated --budgets 16 --cost 1,1.5 "
      "--reference-spp 64 --device cpu --cache-dir {} {}",
      sweep, (dir / "cache").string(), extra);
}

std::string shardPath(const fs::path& dir, int k) { return (dir / fmt::format("shard{}", k)).string(); }

// Shards `ks` of `shards`.
void runShards(const fs::path& dir, const std::string& sweep, const std::string& extra, int shards,
               const std::vector<int>& ks) {
  for (int k : ks) {
    auto r = runMisalloc(
        compareArgs(dir, sweep, fmt::format("{} --shard {}/{} --out-dir {}", extra, k, shards, shardPath(dir, k))));
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
  }
}

std::set<std::string> filesUnder(const fs::path& dir) {
  std::set<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files.insert(fs::relative(e.path(), dir).string());
  return files;
}

// A run's record without what depends on the machine's speed.
nlohmann::json withoutTimes(nlohmann::json run) {
  run.erase("time_s");
  run.erase("efficiency");
  for (auto& stage : run["stages"]) stage.erase("kernel_s");
  return run;
}

// Runs the sweep unsharded into dir/whole, and `shards` shards of it.
void runWholeAndShards(const fs::path& dir, const std::string& sweep, const std::string& extra, int shards) {
  auto whole = runMisalloc(compareArgs(dir, sweep, "--out-dir " + (dir / "whole").string()));
  INFO(whole.output);
  REQUIRE(whole.exitCode == 0);
  std::vector<int> ks(size_t(shards), 0);
  for (int k = 0; k < shards; ++k) ks[size_t(k)] = k;
  runShards(dir, sweep, extra, shards, ks);
}

// Merges `parts` into dir/merged and checks it against dir/whole: the same files, the
// images bit for bit, every run's record but its times (its node included: one machine
// here) and every case's repeats.
void checkMergedIsWhole(const fs::path& dir, const std::vector<std::string>& parts) {
  const fs::path merged = dir / "merged", whole = dir / "whole";
  std::string args = "merge --out-dir " + merged.string();
  for (const std::string& p : parts) args += " " + p;
  auto m = runMisalloc(args);
  INFO(m.output);
  REQUIRE(m.exitCode == 0);
  const std::set<std::string> files = filesUnder(whole);
  CHECK(filesUnder(merged) == files);
  int images = 0;
  for (const std::string& f : files)
    if (f.size() > 4 && (f.substr(f.size() - 4) == ".exr" || f.substr(f.size() - 4) == ".png")) {
      INFO(f);
      CHECK(readText(merged / f) == readText(whole / f));
      ++images;
    }
  CHECK(images > 0);
  const auto wholeRuns = nlohmann::json::parse(readText(whole / "runs.json"));
  const auto mergedRuns = nlohmann::json::parse(readText(merged / "runs.json"));
  REQUIRE(mergedRuns["runs"].size() == wholeRuns["runs"].size());
  for (size_t i = 0; i < wholeRuns["runs"].size(); ++i)
    CHECK(withoutTimes(mergedRuns["runs"][i]) == withoutTimes(wholeRuns["runs"][i]));
  REQUIRE(mergedRuns["cases"].size() == wholeRuns["cases"].size());
  for (size_t i = 0; i < wholeRuns["cases"].size(); ++i) {
    CHECK(mergedRuns["cases"][i]["label"] == wholeRuns["cases"][i]["label"]);
    CHECK(mergedRuns["cases"][i]["repeats"] == wholeRuns["cases"][i]["repeats"]);
  }
}

}  // namespace

// [release-only]: the suite's seven maps, read by six processes, cost minutes under the
// sanitizers; there the next test merges shards of a comparison and runs most of these
// refusals, on one procedural map.
TEST_CASE("merged shards of a comparison are the unsharded run: images bit for bit, errors to the digit",
          "[compare][shard][cli][release-only]") {
  TempDir dir("compare_shard");
  runWholeAndShards(dir.path, kSuite, "", 3);
  checkMergedIsWhole(dir.path, {shardPath(dir.path, 2), shardPath(dir.path, 0), shardPath(dir.path, 1)});

  // Refusals: nothing written, every file as it was.
  fs::create_directories(dir.path / "other");
  runShards(dir.path / "other", kSuite, "--seed 7", 3, {2});  // another run
  fs::create_directories(dir.path / "four");
  runShards(dir.path / "four", kSuite, "", 4, {2});  // another split
  const std::string merge = fmt::format("merge --out-dir {} ", (dir.path / "m").string());
  const std::string s0 = shardPath(dir.path, 0), s1 = shardPath(dir.path, 1), s2 = shardPath(dir.path, 2);
  checkRefusals(
      dir.path,
      {{merge + s0 + " " + s1 + " " + shardPath(dir.path / "other", 2), "shards of different runs"},
       {merge + s0 + " " + s1, "shard 2/3 is missing"},
       {merge + s0 + " " + s1 + " " + s1 + " " + s2, "are the same shard"},
       {merge + s0 + " " + s1 + " " + shardPath(dir.path / "four", 2), "into 3 and 4 shards"},
       {merge + s0 + " " + s1 + " " + (dir.path / "whole").string(), "not a shard of a comparison"},
       {merge + s0 + " " + s1 + " " + s2 + " --out x.exr", "--out FILE.exr"},
       // Shard 0 of 8 has a unit of its own, but shards 7 never will: refused too.
       {compareArgs(dir.path, kSuite, "--shard 0/8 --out-dir " + (dir.path / "m").string()), "fewer than the 8"}},
      dir.path / "m");
}

TEST_CASE("merged shards of a comparison by scene and repeat are the unsharded run, bit for bit",
          "[compare][shard][cli]") {
  // Three units, (sun, repeat 0..2), on two shards: the scene's runs come from both.
  TempDir dir("compare_shard_repeat");
  runWholeAndShards(dir.path, kRepeats, "--shard-unit repeat", 2);
  const std::string s0 = shardPath(dir.path, 0), s1 = shardPath(dir.path, 1);
  checkMergedIsWhole(dir.path, {s1, s0});

  // Refusals: nothing written, every file as it was.
  fs::create_directories(dir.path / "scene");
  // The same run by scene: one shard, as one scene cannot make two.
  runShards(dir.path / "scene", kRepeats, "", 1, {0});
  // Shard 0's folder relabelled as shard 1: both hold repeats 0 and 2.
  const fs::path relabelled = dir.path / "relabelled";
  fs::copy(s0, relabelled, fs::copy_options::recursive);
  auto record = nlohmann::json::parse(readText(relabelled / "shard.json"));
  record["shard"][0] = 1;
  writeText(relabelled / "shard.json", record.dump());
  const std::string merge = fmt::format("merge --out-dir {} ", (dir.path / "m").string());
  const std::string out = " --out-dir " + (dir.path / "m").string();
  checkRefusals(dir.path,
                {{merge + s1 + " " + shardPath(dir.path / "scene", 0), "split the run"},
                 {merge + s1, "shard 0/2 is missing"},
                 {merge + s0 + " " + s0 + " " + s1, "are the same shard"},
                 {merge + s0 + " " + relabelled.string(), "both hold repeat 0 of sun"},
                 {compareArgs(dir.path, kRepeats, "--shard-unit repeat --shard 0/4" + out), "fewer than the 4"},
                 {compareArgs(dir.path, kRepeats, "--shard-unit cube --shard 0/2" + out), "expected scene or repeat"},
                 {compareArgs(dir.path, kRepeats, "--shard-unit repeat" + out), "--shard-unit requires --shard"}},
                dir.path / "m");
}

TEST_CASE("merge reads every run and file of the shards before it writes any, naming what is wrong",
          "[compare][shard][cli][safety]") {
  TempDir dir("compare_shard_files");
  runShards(dir.path, kRepeats, "--shard-unit repeat", 2, {0, 1});
  const std::string s0 = shardPath(dir.path, 0), s1 = shardPath(dir.path, 1);
  std::string exr, png;  // an image and a preview of shard 0, which ran repeat 0
  for (const std::string& f : filesUnder(s0)) {
    if (exr.empty() && f.size() > 4 && f.substr(f.size() - 4) == ".exr") exr = f;
    if (png.empty() && f.size() > 4 && f.substr(f.size() - 4) == ".png") png = f;
  }
  REQUIRE((!exr.empty() && !png.empty()));
  // Copies of shard 0, each damaged once.
  auto damaged = [&](const std::string& name, const std::function<void(const fs::path&)>& damage) {
    const fs::path copy = dir.path / name;
    fs::copy(s0, copy, fs::copy_options::recursive);
    damage(copy);
    return copy.string();
  };
  const std::string deleted = damaged("deleted", [&](const fs::path& c) { fs::remove(c / exr); });
  const std::string flipped = damaged("flipped", [&](const fs::path& c) {
    std::string bytes = readText(c / exr);
    bytes[bytes.size() - 5] ^= 0x10;  // inside the pixels: it still decodes
    writeText(c / exr, bytes);
  });
  const std::string truncated =
      damaged("truncated", [&](const fs::path& c) { writeText(c / exr, readText(c / exr).substr(0, 100)); });
  const std::string emptied = damaged("emptied", [&](const fs::path& c) { writeText(c / png, ""); });
  const std::string stray = damaged("stray", [&](const fs::path& c) { writeText(c / "notes.txt", "mine"); });
  const std::string lostRuns = damaged("lost_runs", [&](const fs::path& c) {
    auto record = nlohmann::json::parse(readText(c / "shard.json"));
    record["runs"].erase(record["runs"].begin(), record["runs"].begin() + 2);
    writeText(c / "shard.json", record.dump());
  });
  const std::string fifo = damaged("fifo", [&](const fs::path& c) {
    fs::remove(c / "shard.json");
    REQUIRE(::mkfifo((c / "shard.json").c_str(), 0600) == 0);
  });
  const std::string merge = fmt::format("merge --out-dir {} ", (dir.path / "m").string());
  checkRefusals(dir.path,
                {{merge + deleted + " " + s1, (fs::path(deleted) / exr).string() + ": missing"},
                 {merge + flipped + " " + s1, (fs::path(flipped) / exr).string() + ": its bytes differ"},
                 {merge + truncated + " " + s1, (fs::path(truncated) / exr).string() + ": its bytes differ"},
                 {merge + emptied + " " + s1, (fs::path(emptied) / png).string() + ": its bytes differ"},
                 {merge + stray + " " + s1, (fs::path(stray) / "notes.txt").string() + ": a file the shard did not"},
                 {merge + lostRuns + " " + s1, lostRuns + "/shard.json: holds 0 runs of"},
                 {merge + fifo + " " + s1, fifo + "/shard.json: not a regular file"},
                 // An output inside a shard, or in its place: refused before any work.
                 {fmt::format("merge --out-dir {}/m {} {}", s0, s0, s1), "lies inside a shard"},
                 {fmt::format("merge --out-dir {} {} {}", s1, s0, s1), "never replaces an input"}},
                dir.path / "m");
  CHECK_FALSE(fs::exists(fs::path(s0) / "m"));
}

TEST_CASE("merge takes shards that spell the run's options differently, and refuses shards of another map's texels",
          "[compare][shard][cli][safety]") {
  TempDir dir("compare_shard_identity");
  // One name in three folders: `a` and `same` hold the same map, `other` another.
  for (const char* folder : {"a", "same", "other"}) {
    fs::create_directories(dir.path / folder);
    const float radiance = folder == std::string("other") ? 0.75f : 0.5f;
    misalloc::writeExr((dir.path / folder / "map.exr").string(),
                       misalloc::RgbImage{8, 4, std::vector<float>(96, radiance)});
  }
  // Shard k of 2, by repeat, from `folder`, into dir/`name`.
  auto shard = [&](const std::string& folder, int k, const std::string& spelled, const std::string& name) {
    auto r = runMisalloc(
        fmt::format("compare --envmap map.exr --repeats 2 --size 8x8 --cost 1,1.5 --reference-spp 64 --device cpu "
                    "--cache-dir {} --shard-unit repeat --shard {}/2 --out-dir {} {}",
                    (dir.path / "cache").string(), k, (dir.path / name).string(), spelled),
        fmt::format("cd {} &&", (dir.path / folder).string()));
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    return (dir.path / name).string();
  };
  const std::string s0 = shard("a", 0, "--methods equal,exact --budgets 16 --envmap-pdfs plain", "s0");
  const std::string s1 =
      shard("same", 1, "--methods equal,exact --budgets 16.0 --envmap-pdfs plain --weights balance --seed 1", "s1");
  const std::string other = shard("other", 1, "--methods equal,exact --budgets 16 --envmap-pdfs plain", "other1");
  auto m = runMisalloc(fmt::format("merge --out-dir {} {} {}", (dir.path / "merged").string(), s0, s1));
  INFO(m.output);
  CHECK(m.exitCode == 0);
  checkRefusals(dir.path,
                {{fmt::format("merge --out-dir {} {} {}", (dir.path / "m").string(), s0, other), "envmap texels"}},
                dir.path / "m");
}
