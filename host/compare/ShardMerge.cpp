#include "compare/ShardMerge.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <numeric>
#include <tuple>

#include "Error.h"
#include "compare/ShardFiles.h"
#include "compare/ShardRecord.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

// Refuses records that are not exactly one run's N complete shards of one unit, each once.
void requireOneRun(const std::vector<std::string>& folders, const std::vector<ShardRecord>& records) {
  const ShardRecord& first = records.front();
  std::vector<int> seen(size_t(first.shard.count), -1);
  for (size_t i = 0; i < records.size(); ++i) {
    const ShardRecord& r = records[i];
    if (r.run != first.run)
      throw InputError(fmt::format("{} and {} are shards of different runs: {}", folders.front(), folders[i],
                                   runDifference(first.run, r.run)));
    if (r.shard.count != first.shard.count)
      throw InputError(fmt::format("{} and {} split the run into {} and {} shards", folders.front(), folders[i],
                                   first.shard.count, r.shard.count));
    if (r.unit != first.unit)
      throw InputError(fmt::format("{} and {} split the run by {} and by {}: merge the shards of one --shard-unit",
                                   folders.front(), folders[i], shardUnitName(first.unit), shardUnitName(r.unit)));
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

// Refuses a case whose runs are not each of its methods at each budget and repeat,
// exactly once: a record that lost or repeated a run would merge into tables that
// compare methods over different samples. The shard that ran a repeat answers for it.
void requireEveryRun(const CaseInfo& info, const std::vector<RunRecord>& runs, const ShardRecord& first,
                     const std::vector<int>& holder, const std::vector<std::string>& folders) {
  for (Method m : first.methods) {
    if (std::any_of(info.leftOut.begin(), info.leftOut.end(), [&](const LeftOutMethod& l) { return l.method == m; }))
      continue;
    for (int budget : first.budgets)
      for (size_t r = 0; r < holder.size(); ++r) {
        const auto n = std::count_if(runs.begin(), runs.end(), [&](const RunRecord& run) {
          return run.method == m && run.budget == budget && run.repeat == int(r);
        });
        if (n != 1)
          throw InputError(fmt::format("{}/{}: holds {} runs of {} {} at {} spp, repeat {}, instead of one",
                                       folders[size_t(holder[r])], kShardRecordFile, n, info.label, methodName(m),
                                       budget, r));
      }
  }
}

const CaseInfo* findCase(const ShardRecord& record, const std::string& label) {
  const auto& cases = record.comparison.cases;
  auto c = std::find_if(cases.begin(), cases.end(), [&](const CaseInfo& i) { return i.label == label; });
  return c == cases.end() ? nullptr : &*c;
}

// Appends the case `label` joined from the shards that ran its repeats, each repeat by
// exactly one, and its runs in the unsharded order. Its record is that of the shard
// that ran repeat 0, whose images the folder holds.
void mergeCase(const std::string& label, int repeats, const std::vector<std::string>& folders,
               const std::vector<ShardRecord>& records, Comparison& merged) {
  std::vector<int> holder(size_t(repeats), -1);  // the record that ran each repeat
  const size_t firstRun = merged.runs.size();
  for (size_t i = 0; i < records.size(); ++i) {
    const CaseInfo* c = findCase(records[i], label);
    if (!c) continue;
    for (int r : c->repeats) {
      if (r < 0 || r >= repeats)
        throw InputError(fmt::format("{}: repeat {} of {} is not one of the run's {}", folders[i], r, label, repeats));
      int& other = holder[size_t(r)];
      if (other >= 0)
        throw InputError(
            fmt::format("{} and {} both hold repeat {} of {}", folders[size_t(other)], folders[i], r, label));
      other = int(i);
    }
    for (const RunRecord& run : records[i].comparison.runs)
      if (run.caseLabel == label) merged.runs.push_back(run);
  }
  for (size_t r = 0; r < holder.size(); ++r)
    if (holder[r] < 0) throw InputError(fmt::format("no shard holds repeat {} of {}", r, label));
  CaseInfo info = *findCase(records[size_t(holder.front())], label);
  requireEveryRun(info, {merged.runs.begin() + std::ptrdiff_t(firstRun), merged.runs.end()}, records.front(), holder,
                  folders);
  info.repeats.resize(size_t(repeats));
  std::iota(info.repeats.begin(), info.repeats.end(), 0);
  merged.cases.push_back(std::move(info));
  // Budget, then repeat, then method: within a repeat, its shard's order.
  std::stable_sort(merged.runs.begin() + std::ptrdiff_t(firstRun), merged.runs.end(),
                   [](const RunRecord& a, const RunRecord& b) {
                     return std::tie(a.budget, a.repeat) < std::tie(b.budget, b.repeat);
                   });
}

}  // namespace

MergedComparison mergeShards(const std::vector<std::string>& folders) {
  std::vector<ShardRecord> records;
  for (const std::string& folder : folders) records.push_back(readShardRecord(folder));
  requireOneRun(folders, records);
  for (size_t i = 0; i < folders.size(); ++i) requireShardFiles(folders[i], records[i]);
  const ShardRecord& first = records.front();
  MergedComparison merged;
  merged.options.methods = first.methods;
  merged.options.budgets = first.budgets;
  merged.options.repeats = first.repeats;
  merged.options.tableBudget = first.tableBudget;
  for (const std::string& label : first.manifest) mergeCase(label, first.repeats, folders, records, merged.comparison);
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
