#include "OutputSet.h"

#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "AtomicFile.h"
#include "Error.h"

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

// The folder itself, without a trailing slash, as an absolute path.
fs::path folderPath(const std::string& folder) {
  fs::path p = fs::absolute(folder).lexically_normal();
  return p.has_filename() ? p : p.parent_path();
}

// A new, empty folder beside `folder`, hidden and named with ".tmp" like the
// temporary files; mkdir fails on an existing name, so nothing is ever reused.
std::string makeStagingFolder(const fs::path& folder) {
  for (int attempt = 0;; ++attempt) {
    fs::path staging =
        folder.parent_path() / fmt::format(".{}.tmp-{}-{}", folder.filename().string(), ::getpid(), attempt);
    if (::mkdir(staging.c_str(), 0777) == 0) return staging.string();
    if (errno != EEXIST) throw InputError(fmt::format("cannot create {}: {}", staging.string(), std::strerror(errno)));
  }
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
  for (const NamedFile& input : inputs_)
    if (sameFile(output.path, input.path))
      throw InputError(fmt::format("{} {} is the same file as {} {}: an output never replaces an input", output.option,
                                   output.path, input.option, input.path));
  for (const NamedFile& other : outputs_)
    if (sameFile(output.path, other.path))
      throw InputError(fmt::format("{} {} and {} {} are the same file: each output needs a file of its own",
                                   output.option, output.path, other.option, other.path));
}

void OutputSet::claim(const std::string& option, const std::string& path) {
  checkWritableOutput(path, option);
  refuseClashes({option, path});
  outputs_.push_back({option, path});
}

std::string OutputSet::claimFolder(const std::string& option, const std::string& folder) {
  if (!staging_.empty()) throw std::logic_error("OutputSet: one folder per run");
  fs::path target = folderPath(folder);
  std::error_code ec;
  if (fs::exists(target, ec) && !fs::is_directory(target, ec))
    throw InputError(fmt::format("{} {}: is a file, not a folder", option, folder));
  fs::create_directories(target.parent_path(), ec);
  if (ec) throw InputError(fmt::format("{} {}: cannot create {}: {}", option, folder, target.parent_path().string(), ec.message()));
  for (const fs::path& dir : {target.parent_path(), target})
    if (fs::exists(dir) && ::access(dir.c_str(), W_OK) != 0)
      throw InputError(fmt::format("{} {}: folder {} is not writable", option, folder, dir.string()));
  folder_ = target.string();
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

std::vector<OutputSet::StagedFile> OutputSet::stagedFolderFiles() const {
  std::vector<StagedFile> files;
  if (staging_.empty()) return files;
  for (const auto& entry : fs::recursive_directory_iterator(staging_)) {
    if (!entry.is_regular_file()) continue;
    fs::path target = fs::path(folder_) / entry.path().lexically_relative(staging_);
    for (const NamedFile& input : inputs_)
      if (sameFile(target.string(), input.path))
        throw InputError(fmt::format("{} would replace {} {}: an output never replaces an input", target.string(),
                                     input.option, input.path));
    if (fs::is_directory(target))
      throw InputError(fmt::format("cannot write {}: a folder of that name is in the way", target.string()));
    files.push_back({target.string(), entry.path().string()});
  }
  return files;
}

void OutputSet::commit() {
  for (const NamedFile& output : outputs_)
    if (contents_.count(output.path) == 0) throw std::logic_error("OutputSet: nothing to write to " + output.path);
  // Everything that can fail happens before the first rename.
  std::vector<StagedFile> files = stagedFolderFiles();
  for (const StagedFile& file : files) {  // claimed files' folders exist: claim() checked
    std::error_code ec;
    fs::create_directories(fs::path(file.target).parent_path(), ec);
    if (ec) throw InputError(fmt::format("cannot write {}: {}", file.target, ec.message()));
  }
  for (const auto& [path, content] : contents_) {
    temporaries_.push_back(writeTemporaryBeside(path, content));
    files.push_back({path, temporaries_.back()});
  }
  for (const StagedFile& file : files) renameIntoPlace(file.temporary, file.target);
  temporaries_.clear();
  std::error_code ignored;
  if (!staging_.empty()) fs::remove_all(staging_, ignored);
  staging_.clear();
}

}  // namespace misalloc
