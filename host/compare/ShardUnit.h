#pragma once
// What a shard of a comparison (compare --shard K/N --shard-unit) runs. The units are
// whole scenes, or (scene, repeat) pairs with every method, envmap pdf and budget of
// that repeat, in the unsharded run's order; unit u goes to shard u mod N.
#include <string>
#include <vector>

#include "Shard.h"
#include "compare/Comparison.h"

namespace misalloc {

enum class ShardUnit {
  Scene,   // every timing ratio of a scene measured on one node
  Repeat,  // more units than scenes; the ratios of one repeat on one node
};

// "scene" or "repeat"; throws InputError naming `option` otherwise.
ShardUnit parseShardUnit(const std::string& name, const std::string& option);
const char* shardUnitName(ShardUnit unit);

// The scenes (before their envmap pdfs) that `shard` runs, each with the repeats it runs
// of them (CompareCase::repeats); the whole run for Shard{}. Throws InputError when the
// run has fewer units than shards, whichever shard asks: one of them would have none.
std::vector<CompareCase> shardCases(const std::vector<CompareCase>& scenes, int repeats, ShardUnit unit, Shard shard);

}  // namespace misalloc
