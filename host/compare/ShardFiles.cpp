#include "compare/ShardFiles.h"

#include <fmt/format.h>

#include <filesystem>
#include <set>

#include "ContentHash.h"
#include "Error.h"
#include "compare/ShardRecord.h"
#include "report/AlphaMap.h"
#include "report/PreviewPng.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

std::string fileChecksum(const fs::path& path) {
  return fmt::format("{:016x}", fileContentHash(path.string(), path.string()));
}

// What the shard's cases and runs write (compare/Comparison.cpp): each case's reference
// preview, and each repeat-0 run's image and preview, and α map and its picture if the
// method allocates; and the runs so far.
std::set<std::string> expectedFiles(const ShardRecord& record) {
  std::set<std::string> files{"runs.json", "runs.csv"};
  for (const CaseInfo& c : record.comparison.cases) files.insert(c.label + "/reference.png");
  for (const RunRecord& r : record.comparison.runs) {
    if (r.repeat != 0) continue;
    const std::string image = imagePath(r.caseLabel, r.method, r.budget);
    files.insert({image, previewPath(image)});
    if (isAdaptive(r.method)) {
      const std::string alpha = alphaMapPath(r.caseLabel, r.method, r.budget);
      files.insert({alpha, alphaPngPath(alpha)});
    }
  }
  return files;
}

}  // namespace

std::map<std::string, std::string> shardFileChecksums(const std::string& folder) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    const std::string name = fs::relative(entry.path(), folder).string();
    if (entry.is_regular_file() && name != kShardRecordFile) files[name] = fileChecksum(entry.path());
  }
  return files;
}

void requireShardFiles(const std::string& folder, const ShardRecord& record) {
  for (const std::string& name : expectedFiles(record))
    if (!record.files.count(name))
      throw InputError(fmt::format("{}: its {} lists no {}, which its runs write", folder, kShardRecordFile, name));
  std::set<std::string> seen;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    const std::string name = fs::relative(entry.path(), folder).string(), path = entry.path().string();
    if (entry.symlink_status().type() == fs::file_type::directory) continue;
    if (name == kShardRecordFile) continue;
    if (entry.symlink_status().type() != fs::file_type::regular)
      throw InputError(fmt::format("{}: not a regular file; a shard holds the files it wrote", path));
    const auto listed = record.files.find(name);
    if (listed == record.files.end())
      throw InputError(fmt::format("{}: a file the shard did not write (its {} does not list it); remove it", path,
                                   kShardRecordFile));
    if (fileChecksum(entry.path()) != listed->second)
      throw InputError(
          fmt::format("{}: its bytes differ from those the shard wrote (damaged or replaced); run the "
                      "shard again",
                      path));
    seen.insert(name);
  }
  for (const auto& [name, checksum] : record.files)
    if (!seen.count(name))
      throw InputError(fmt::format("{}: missing; the shard wrote it (its {} lists it)",
                                   (fs::path(folder) / name).string(), kShardRecordFile));
}

}  // namespace misalloc
