#include "OutputSet.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include "AtomicFile.h"
#include "Error.h"
#include "Interruption.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

// The path with `./`, `..` and the symbolic links of its existing part resolved.
fs::path resolved(const std::string& path) {
  std::error_code ec;
  fs::path absolute = fs::absolute(path, ec);
  if (ec) return fs::path(path).lexically_normal();
  fs::path canonical = fs::weakly_canonical(absolute, ec);
  return ec ? absolute.lexically_normal() : canonical;
}

// Whether `path` is `folder` or lies below it, both resolved.
bool insideFolder(const std::string& path, const fs::path& folder) {
  const fs::path p = resolved(path);
  auto f = folder.begin(), q = p.begin();
  for (; f != folder.end(); ++f, ++q)
    if (q == p.end() || *q != *f) return false;
  return true;
}

// A new, empty folder beside `folder`, named as the temporary files are; mkdir fails
// on an existing name, so nothing is ever reused.
std::string makeStagingFolder(const fs::path& folder) {
  removeStaleTemporaries(folder.parent_path().string());
  for (int attempt = 0;; ++attempt) {
    const std::string staging = temporaryName(folder.string(), attempt);
    if (::mkdir(staging.c_str(), 0777) == 0) return staging;
    if (errno != EEXIST) throw InputError(fmt::format("cannot create {}: {}", staging, std::strerror(errno)));
  }
}

// tests/test_safety.cpp signals a run while its commit pauses here, between renames.
void pauseForTests() {
  if (const char* ms = std::getenv("MISALLOC_TEST_COMMIT_PAUSE_MS"))
    std::this_thread::sleep_for(std::chrono::milliseconds(std::atoi(ms)));
}

}  // namespace

bool sameFile(const std::string& a, const std::string& b) {
  if (resolved(a) == resolved(b)) return true;
  std::error_code ec;
  return fs::equivalent(a, b, ec) && !ec;
}

OutputSet::OutputSet(std::vector<NamedFile> inputs) : inputs_(std::move(inputs)) {}

OutputSet::~OutputSet() {
  for (const std::string& tmp : temporaries_) std::remove(tmp.c_str());
  std::error_code ignored;
  if (!staging_.empty()) fs::remove_all(staging_, ignored);
}

void OutputSet::refuseClashes(const NamedFile& output) const {
  std::error_code ec;
  for (const NamedFile& input : inputs_) {
    if (sameFile(output.path, input.path))
      throw InputError(fmt::format("{} {} is the same file as {} {}: an output never replaces an input", output.option,
                                   output.path, input.option, input.path));
    // An input read as a folder (a shard) reads what lies inside it: an output there
    // would change it, or be copied into itself.
    if (fs::is_directory(input.path, ec) && insideFolder(output.path, resolved(input.path)))
      throw InputError(fmt::format("{} {} lies inside {} {}: an output never replaces an input; choose another place",
                                   output.option, output.path, input.option, input.path));
  }
  for (const NamedFile& other : outputs_)
    if (sameFile(output.path, other.path))
      throw InputError(fmt::format("{} {} and {} {} are the same file: each output needs a file of its own",
                                   output.option, output.path, other.option, other.path));
}

void OutputSet::refuseInputInFolder(const NamedFile& input) const {
  if (!folder_.empty() && insideFolder(input.path, folder_))
    throw InputError(
        fmt::format("{} {} lies inside {} {}, which the run replaces as a whole: an output never "
                    "replaces an input; choose another folder",
                    input.option, input.path, folderOption_, folder_));
}

void OutputSet::claim(const std::string& option, const std::string& path) {
  checkWritableOutput(path, option);
  refuseClashes({option, path});
  outputs_.push_back({option, path});
}

void OutputSet::addInput(const NamedFile& input) {
  for (const NamedFile& output : outputs_)
    if (sameFile(output.path, input.path))
      throw InputError(fmt::format("{} {} is the same file as {} {}: an output never replaces an input", output.option,
                                   output.path, input.option, input.path));
  refuseInputInFolder(input);
  inputs_.push_back(input);
}

std::string OutputSet::claimFolder(const std::string& option, const std::string& folder, const std::string& marker) {
  if (!staging_.empty()) throw std::logic_error("OutputSet: one folder per run");
  if (folder.empty()) throw InputError(fmt::format("{}: an empty path", option));
  const fs::path target = resolved(folder);
  std::error_code ec;
  if (fs::exists(target, ec) && !fs::is_directory(target, ec))
    throw InputError(fmt::format("{} {}: is a file, not a folder", option, folder));
  if (fs::is_directory(target, ec) && !fs::is_empty(target, ec) && !fs::exists(target / marker, ec))
    throw InputError(
        fmt::format("{} {}: holds files that no earlier run of this command wrote (no {}); the run "
                    "replaces the folder as a whole: give a new or empty folder",
                    option, folder, marker));
  refuseClashes({option, folder});
  folderOption_ = option;
  folder_ = target.string();
  for (const NamedFile& input : inputs_) refuseInputInFolder(input);
  fs::create_directories(target.parent_path(), ec);
  if (ec)
    throw InputError(
        fmt::format("{} {}: cannot create {}: {}", option, folder, target.parent_path().string(), ec.message()));
  for (const fs::path& dir : {target.parent_path(), target})
    if (fs::exists(dir) && ::access(dir.c_str(), W_OK) != 0)
      throw InputError(fmt::format("{} {}: folder {} is not writable", option, folder, dir.string()));
  staging_ = makeStagingFolder(target);
  return staging_;
}

void OutputSet::put(const std::string& path, std::string content) {
  for (const NamedFile& output : outputs_)
    if (output.path == path) {
      contents_[path] = std::move(content);
      return;
    }
  throw std::logic_error("OutputSet: " + path + " was not claimed");
}

// The staging folder takes the folder's name in one step: renameat2 exchanges the two
// where the file system can, and the old folder then goes under the staging name. Where
// it cannot (EINVAL: NFS and others), the old folder is first moved aside, and for that
// moment the folder is missing, never mixed.
void OutputSet::replaceFolder() {
  if (!fs::exists(folder_)) {
    renameIntoPlace(staging_, folder_);
  } else if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, folder_.c_str(), RENAME_EXCHANGE) != 0) {
    if (errno != EINVAL && errno != ENOSYS)
      throw InputError(fmt::format("cannot replace {}: {}", folder_, std::strerror(errno)));
    const std::string aside = makeStagingFolder(folder_);
    fs::rename(folder_, fs::path(aside) / "old");
    renameIntoPlace(staging_, folder_);
    staging_ = aside;
  }
  pauseForTests();
}

void OutputSet::commit() {
  for (const NamedFile& output : outputs_)
    if (contents_.count(output.path) == 0) throw std::logic_error("OutputSet: nothing to write to " + output.path);
  std::vector<StagedFile> files;
  for (const auto& [path, content] : contents_) {
    temporaries_.push_back(writeTemporaryBeside(path, content));
    files.push_back({path, temporaries_.back()});
  }
  {
    CriticalSection renaming;
    for (const StagedFile& file : files) {
      renameIntoPlace(file.temporary, file.target);
      pauseForTests();
    }
    temporaries_.clear();
    if (!staging_.empty()) replaceFolder();
  }
  std::error_code ignored;
  if (!staging_.empty()) fs::remove_all(staging_, ignored);  // the old folder, where one was replaced
  staging_.clear();
}

}  // namespace misalloc
