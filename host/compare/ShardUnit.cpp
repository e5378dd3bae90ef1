#include "compare/ShardUnit.h"

#include <fmt/format.h>

#include "Error.h"

namespace misalloc {

ShardUnit parseShardUnit(const std::string& name, const std::string& option) {
  if (name == "scene") return ShardUnit::Scene;
  if (name == "repeat") return ShardUnit::Repeat;
  throw InputError(fmt::format("{} '{}': expected scene or repeat", option, name));
}

const char* shardUnitName(ShardUnit unit) { return unit == ShardUnit::Scene ? "scene" : "repeat"; }

std::vector<CompareCase> shardCases(const std::vector<CompareCase>& scenes, int repeats, ShardUnit unit, Shard shard) {
  // Every shard must hold a unit, or the merge can never complete: refused before any work
  // whichever shard asks.
  const size_t units = unit == ShardUnit::Scene ? scenes.size() : scenes.size() * size_t(repeats);
  if (units < size_t(shard.count)) {
    const std::string what =
        unit == ShardUnit::Scene
            ? fmt::format("{} scene(s)", scenes.size())
            : fmt::format("{} (scene, repeat) units ({} scene(s) x {} repeat(s))", units, scenes.size(), repeats);
    throw InputError(fmt::format("--shard {}/{}: the comparison has {}, fewer than the {} shards{}", shard.index,
                                 shard.count, what, shard.count,
                                 unit == ShardUnit::Scene ? " (--shard-unit repeat splits a scene by repeat)" : ""));
  }
  std::vector<CompareCase> out;
  for (size_t i = 0; i < scenes.size(); ++i) {
    CompareCase c = scenes[i];
    c.repeats.clear();
    for (int r = 0; r < repeats; ++r) {
      // The unit in the unsharded run's order: scene i, or its repeat r.
      const size_t u = unit == ShardUnit::Scene ? i : i * size_t(repeats) + size_t(r);
      if (u % size_t(shard.count) == size_t(shard.index)) c.repeats.push_back(r);
    }
    if (!c.repeats.empty()) out.push_back(std::move(c));
  }
  return out;
}

}  // namespace misalloc
