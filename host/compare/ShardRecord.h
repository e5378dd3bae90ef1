#pragma once
// The record a shard of a comparison (compare --shard K/N) leaves in its folder for
// `misalloc merge --out-dir`.
#include <map>
#include <string>
#include <vector>

#include "Shard.h"
#include "compare/Comparison.h"
#include "compare/ShardUnit.h"

namespace misalloc {

// The file that makes a folder a shard's.
inline constexpr const char* kShardRecordFile = "shard.json";

struct ShardRecord {
  std::string run;  // the run's identity (cli/RunIdentity.h): shards of one run share it
  Shard shard;
  ShardUnit unit = ShardUnit::Scene;
  std::vector<std::string> manifest;  // every case's label, in the unsharded run's order
  std::vector<Method> methods;
  std::vector<int> budgets;
  int repeats = 0, tableBudget = 0;
  Comparison comparison;  // this shard's cases (with the repeats it ran) and runs, every number as measured
  std::map<std::string, std::string> files;  // what it wrote, with checksums (compare/ShardFiles.h)
};

std::string shardRecordJson(const ShardRecord& record);

// The record in `folder`; throws InputError naming the folder when it has none, or one
// that is not a regular file or cannot be read.
ShardRecord readShardRecord(const std::string& folder);

}  // namespace misalloc
