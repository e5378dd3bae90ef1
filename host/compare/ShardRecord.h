#pragma once
// A shard of a comparison (compare --shard K/N): which scenes it runs, and the record
// it leaves in its folder for `misalloc merge --out-dir`.
#include <string>
#include <vector>

#include "Shard.h"
#include "compare/Comparison.h"

namespace misalloc {

// The file that makes a folder a shard's.
inline constexpr const char* kShardRecordFile = "shard.json";

// The scenes (before their envmap pdfs) shard K of N runs: scene i where i mod N = K,
// so that a scene's methods, pdfs, budgets and repeats run in one process on one node
// and every timing ratio is measured on one machine. Throws InputError when the shard
// would have no scene.
std::vector<CompareCase> shardScenes(const std::vector<CompareCase>& scenes, Shard shard);

struct ShardRecord {
  std::string run;  // the run's identity (cli/RunIdentity.h): shards of one run share it
  Shard shard;
  std::vector<std::string> manifest;  // every case's label, in the unsharded run's order
  std::vector<Method> methods;
  std::vector<int> budgets;
  int repeats = 0, tableBudget = 0;
  Comparison comparison;  // this shard's cases and runs, every number as measured
};

std::string shardRecordJson(const ShardRecord& record);

// The record in `folder`; throws InputError naming the folder when it has none, or one
// that cannot be read.
ShardRecord readShardRecord(const std::string& folder);

}  // namespace misalloc
