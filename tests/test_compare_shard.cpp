// A sharded comparison: shards of whole scenes merged into the unsharded run's folder,
// its images bit for bit and its errors to the digit (times excluded), and merge's
// refusals of folders that do not make one run.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "CliRunner.h"
#include "SafetyWorkspace.h"

using namespace misalloc::test;

namespace {

std::string compareArgs(const fs::path& dir, const std::string& extra) {
  return fmt::format(
      "compare --suite --size 8x8 --methods equal,exact --envmap-pdfs plain,compensated --budgets 16,24 --repeats 1 "
      "--cost 1,1.5 --reference-spp 64 --device cpu --cache-dir {} {}",
      (dir / "cache").string(), extra);
}

std::string shardPath(const fs::path& dir, int k) { return (dir / fmt::format("shard{}", k)).string(); }

// Shards `ks` of `shards`.
void runShards(const fs::path& dir, const std::string& extra, int shards, const std::vector<int>& ks) {
  for (int k : ks) {
    auto r = runMisalloc(
        compareArgs(dir, fmt::format("{} --shard {}/{} --out-dir {}", extra, k, shards, shardPath(dir, k))));
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

}  // namespace

TEST_CASE("merged shards of a comparison are the unsharded run: images bit for bit, errors to the digit",
          "[compare][shard][cli]") {
  TempDir dir("compare_shard");
  auto whole = runMisalloc(compareArgs(dir.path, "--out-dir " + (dir.path / "whole").string()));
  INFO(whole.output);
  REQUIRE(whole.exitCode == 0);
  runShards(dir.path, "", 3, {0, 1, 2});
  const fs::path merged = dir.path / "merged";
  auto m = runMisalloc(fmt::format("merge --out-dir {} {} {} {}", merged.string(), shardPath(dir.path, 2),
                                   shardPath(dir.path, 0), shardPath(dir.path, 1)));
  INFO(m.output);
  REQUIRE(m.exitCode == 0);
  const std::set<std::string> files = filesUnder(dir.path / "whole");
  CHECK(filesUnder(merged) == files);
  int images = 0;
  for (const std::string& f : files)
    if (f.size() > 4 && (f.substr(f.size() - 4) == ".exr" || f.substr(f.size() - 4) == ".png")) {
      INFO(f);
      CHECK(readText(merged / f) == readText(dir.path / "whole" / f));
      ++images;
    }
  CHECK(images > 0);
  const auto wholeRuns = nlohmann::json::parse(readText(dir.path / "whole" / "runs.json"));
  const auto mergedRuns = nlohmann::json::parse(readText(merged / "runs.json"));
  REQUIRE(mergedRuns["runs"].size() == wholeRuns["runs"].size());
  for (size_t i = 0; i < wholeRuns["runs"].size(); ++i)
    CHECK(withoutTimes(mergedRuns["runs"][i]) == withoutTimes(wholeRuns["runs"][i]));
  REQUIRE(mergedRuns["cases"].size() == wholeRuns["cases"].size());
  for (size_t i = 0; i < wholeRuns["cases"].size(); ++i) {
    CHECK(mergedRuns["cases"][i]["label"] == wholeRuns["cases"][i]["label"]);
    CHECK(mergedRuns["cases"][i]["node"] == wholeRuns["cases"][i]["node"]);  // one machine here
  }

  // Refusals: nothing written, every file as it was.
  fs::create_directories(dir.path / "other");
  runShards(dir.path / "other", "--seed 7", 3, {2});  // another run
  fs::create_directories(dir.path / "four");
  runShards(dir.path / "four", "", 4, {2});  // another split
  const std::string merge = fmt::format("merge --out-dir {} ", (dir.path / "m").string());
  const std::string s0 = shardPath(dir.path, 0), s1 = shardPath(dir.path, 1), s2 = shardPath(dir.path, 2);
  checkRefusals(dir.path,
                {{merge + s0 + " " + s1 + " " + shardPath(dir.path / "other", 2), "shards of different runs"},
                 {merge + s0 + " " + s1, "shard 2/3 is missing"},
                 {merge + s0 + " " + s1 + " " + s1 + " " + s2, "are the same shard"},
                 {merge + s0 + " " + s1 + " " + shardPath(dir.path / "four", 2), "into 3 and 4 shards"},
                 {merge + s0 + " " + s1 + " " + (dir.path / "whole").string(), "not a shard of a comparison"},
                 {merge + s0 + " " + s1 + " " + s2 + " --out x.exr", "--out FILE.exr"},
                 {compareArgs(dir.path, "--shard 7/8 --out-dir " + (dir.path / "m").string()), "fewer than the 8"}},
                dir.path / "m");
}
