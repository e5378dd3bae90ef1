#include "compare/ShardMerge.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "Error.h"
#include "compare/ShardRecord.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

// Refuses records that are not exactly one run's N complete shards, each once.
void requireOneRun(const std::vector<std::string>& folders, const std::vector<ShardRecord>& records) {
  const ShardRecord& first = records.front();
  std::vector<int> seen(size_t(first.shard.count), -1);
  for (size_t i = 0; i < records.size(); ++i) {
    const ShardRecord& r = records[i];
    if (r.run != first.run)
      throw InputError(fmt::format("{} and {} are shards of different runs: '{}' and '{}'", folders.front(), folders[i],
                                   first.run, r.run));
    if (r.shard.count != first.shard.count)
      throw InputError(fmt::format("{} and {} split the run into {} and {} shards", folders.front(), folders[i],
                                   first.shard.count, r.shard.count));
    if (r.comparison.interrupted)
      throw InputError(
          fmt::format("{}: shard {}/{} was interrupted; run it again", folders[i], r.shard.index, r.shard.count));
    int& other = seen[size_t(r.shard.index)];
    if (other >= 0)
      throw InputError(fmt::format("{} and {} are the same shard, {}/{}", folders[size_t(other)], folders[i],
                                   r.shard.index, r.shard.count));
    other = int(i);
  }
  for (size_t k = 0; k < seen.size(); ++k)
    if (seen[k] < 0) throw InputError(fmt::format("shard {}/{} is missing", k, first.shard.count));
}

}  // namespace

MergedComparison mergeShards(const std::vector<std::string>& folders) {
  std::vector<ShardRecord> records;
  for (const std::string& folder : folders) records.push_back(readShardRecord(folder));
  requireOneRun(folders, records);
  const ShardRecord& first = records.front();
  MergedComparison merged;
  merged.options.methods = first.methods;
  merged.options.budgets = first.budgets;
  merged.options.repeats = first.repeats;
  merged.options.tableBudget = first.tableBudget;
  // The cases in the manifest's order, each with its runs in the order its shard ran them.
  for (const std::string& label : first.manifest) {
    for (const ShardRecord& r : records) {
      const auto& cases = r.comparison.cases;
      auto c = std::find_if(cases.begin(), cases.end(), [&](const CaseInfo& i) { return i.label == label; });
      if (c == cases.end()) continue;
      merged.comparison.cases.push_back(*c);
      for (const RunRecord& run : r.comparison.runs)
        if (run.caseLabel == label) merged.comparison.runs.push_back(run);
    }
  }
  if (merged.comparison.cases.size() != first.manifest.size())
    throw InputError(
        fmt::format("the shards hold {} of the run's {} cases", merged.comparison.cases.size(), first.manifest.size()));
  return merged;
}

void copyShardFiles(const std::string& folder, const std::string& outDir) {
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    const fs::path relative = fs::relative(entry.path(), folder);
    const std::string name = relative.string();
    if (name == kShardRecordFile || name == "runs.json" || name == "runs.csv") continue;
    if (entry.is_directory())
      fs::create_directories(fs::path(outDir) / relative);
    else
      fs::copy_file(entry.path(), fs::path(outDir) / relative, fs::copy_options::overwrite_existing);
  }
}

}  // namespace misalloc
