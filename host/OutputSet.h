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
// is not a regular file, or its folder is missing or not writable. Its content is then
// handed over, and commit() writes every file to a temporary beside its target and
// only when all are complete renames them into place, inside a CriticalSection
// (Interruption.h): SIGINT and SIGTERM wait for the renames. A run that throws before
// commit() leaves every existing file as it was, and the destructor removes what it
// staged; what SIGKILL leaves is removed by the next run that writes there.
class OutputSet {
 public:
  explicit OutputSet(std::vector<NamedFile> inputs);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  void claim(const std::string& option, const std::string& path);

  // An input known only once the run's options are read (the reference cache's entry):
  // refused like the others if an output is the same file or lies in the claimed folder.
  void addInput(const NamedFile& input);

  // Claims a folder that the run fills as it goes (compare's --out-dir) and returns a
  // fresh staging folder beside it to write into; commit() replaces `folder` with it
  // as a whole, by exchanging the two in one rename. Refused when an input lies inside
  // `folder`, or when `folder` holds files but not `marker`, the file that says an
  // earlier run of the same command wrote it: replacing it would delete the user's own.
  std::string claimFolder(const std::string& option, const std::string& folder, const std::string& marker);

  // The content of a claimed file, written at commit().
  void put(const std::string& path, std::string content);

  void commit();

 private:
  struct StagedFile {
    std::string target, temporary;
  };

  void refuseClashes(const NamedFile& output) const;
  void refuseInputInFolder(const NamedFile& input) const;
  void replaceFolder();

  std::vector<NamedFile> inputs_, outputs_;
  std::map<std::string, std::string> contents_;  // claimed path → content
  std::string folderOption_, folder_, staging_;  // claimFolder's option, target and staging folder
  std::vector<std::string> temporaries_;         // written, not yet renamed
};

}  // namespace misalloc
