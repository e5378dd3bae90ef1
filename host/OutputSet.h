#pragma once
// All of a run's outputs, or none of them.
#include <map>
#include <string>
#include <vector>

namespace misalloc {

// A file a run reads or writes, with the option that named it, for messages.
struct NamedFile {
  std::string option;  // "--out", "--envmap", ...
  std::string path;
};

// Whether `a` and `b` are one file: the same path once `./`, `..` and symbolic links
// are resolved, or, when both exist, the same device and inode (hard links).
bool sameFile(const std::string& a, const std::string& b);

// The outputs of one run, written all or none. Each output is claimed before any work
// and refused (InputError) if it is the same file as an input or as another output,
// or its folder is missing or not writable. Its content is then handed over, and
// commit() writes every file to a temporary beside its target and only when all are
// complete renames them into place. A run that throws before commit() leaves every
// existing file as it was, and the destructor removes what it staged.
class OutputSet {
 public:
  explicit OutputSet(std::vector<NamedFile> inputs);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  void claim(const std::string& option, const std::string& path);

  // Claims a folder that the run fills as it goes (compare's --out-dir): returns a
  // fresh staging folder to write into; commit() moves its files into `folder`,
  // creating it if missing, after checking that none of them replaces an input.
  std::string claimFolder(const std::string& option, const std::string& folder);

  // The content of a claimed file, written at commit().
  void put(const std::string& path, std::string content);

  void commit();

 private:
  struct StagedFile {
    std::string target, temporary;
  };

  void refuseClashes(const NamedFile& output) const;
  std::vector<StagedFile> stagedFolderFiles() const;

  std::vector<NamedFile> inputs_, outputs_;
  std::map<std::string, std::string> contents_;  // claimed path → content
  std::string folder_, staging_;                 // claimFolder's target and staging folder
  std::vector<std::string> temporaries_;         // written, not yet renamed
};

}  // namespace misalloc
