#pragma once
#include <functional>
#include <string>

namespace misalloc {

// An exclusive lock on a file, held from construction to destruction, that processes
// on several machines respect: a POSIX record lock (fcntl), which NFS carries to the
// server's lock manager where flock would stay local to one client. The lock file is
// created if absent and left in place: removing it would let a process that opened the
// old file and one that creates a new one both hold "the" lock. The kernel releases
// the lock when its process ends, however it ends. Throws InputError naming `path`
// when the file cannot be opened or locked. `onWait`, if given, is called once before
// waiting when another process holds the lock.
class FileLock {
 public:
  explicit FileLock(const std::string& path, const std::function<void()>& onWait = {});
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace misalloc
