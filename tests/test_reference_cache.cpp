// The reference cache shared by concurrent processes (shards on a shared file system):
// one computes an entry while the others wait for it and read it.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <optional>

#include "CliRunner.h"
#include "FileLock.h"
#include "SafetyWorkspace.h"
#include "Spawn.h"
#include "render/Reference.h"
#include "scene/Scene.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

int occurrences(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("processes sharing the reference cache compute an entry once, one at a time", "[cli][cache]") {
  TempDir dir("reference_cache");
  const std::string cache = (dir.path / "cache").string();
  SceneOptions options;
  options.envmap = "sun";
  options.width = options.height = 8;
  const int spp = 256;
  const std::string entry = *referenceCachePath(makeScene(options), spp, cache);
  const fs::path lock = fs::path(cache) / "locks" / fs::path(entry).stem().concat(".lock");
  fs::create_directories(lock.parent_path());
  constexpr int kProcesses = 3;
  std::vector<pid_t> pids;
  {
    // This process holds the entry's lock, as a shard computing it would, until every
    // other process has found it held: they then all race for it at once.
    FileLock held(lock.string());
    for (int i = 0; i < kProcesses; ++i)
      pids.push_back(
          spawnMisalloc(fmt::format("reference --envmap sun --size 8x8 --spp {} --device cpu --cache-dir {} --out {}",
                                    spp, cache, (dir.path / fmt::format("ref{}.exr", i)).string()),
                        "", (dir.path / fmt::format("log{}", i)).string()));
    REQUIRE(waitFor([&] {
      for (int i = 0; i < kProcesses; ++i)
        if (readText(dir.path / fmt::format("log{}", i)).find("waiting for it") == std::string::npos) return false;
      return true;
    }));
    CHECK_FALSE(fs::exists(entry));
  }
  std::string logs;
  for (pid_t pid : pids) {
    const int status = waitStatus(pid);
    CHECK((WIFEXITED(status) && WEXITSTATUS(status) == 0));
  }
  for (int i = 0; i < kProcesses; ++i) logs += readText(dir.path / fmt::format("log{}", i));
  INFO(logs);
  CHECK(occurrences(logs, "misalloc: computing the reference") == 1);
  CHECK(occurrences(logs, "(cached) at " + entry) == kProcesses - 1);
  CHECK_FALSE(holdsTemporaries(dir.path));
  // Every process has the one entry, bit for bit.
  const std::string first = readText(dir.path / "ref0.exr");
  REQUIRE_FALSE(first.empty());
  for (int i = 1; i < kProcesses; ++i) CHECK(readText(dir.path / fmt::format("ref{}.exr", i)) == first);
}
