#pragma once
// The shards of a comparison (compare --shard K/N) joined into the comparison the
// unsharded run makes: its cases and runs in the unsharded order, and every file the
// shards wrote.
#include <string>
#include <vector>

#include "compare/Comparison.h"

namespace misalloc {

struct MergedComparison {
  CompareOptions options;  // what the summary reads: methods, budgets, repeats, the table's budget
  Comparison comparison;
};

// Throws InputError, naming the folder or file, for a folder that is not a shard, shards
// of different runs (options, versions or inputs) or units, a shard given twice or
// missing, a repeat of a case that no shard or two shards hold, a run missing or held
// twice, a shard's file missing, damaged or not its own (compare/ShardFiles.h), and an
// interrupted shard. Reads every file before the merge writes any.
MergedComparison mergeShards(const std::vector<std::string>& folders);

// Copies what the shard in `folder` wrote of its cases (images, α maps, previews) into
// `outDir`; its record and its runs files, which the merge writes whole, are left out.
void copyShardFiles(const std::string& folder, const std::string& outDir);

}  // namespace misalloc
