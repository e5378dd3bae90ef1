#include "FileLock.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "Error.h"

namespace misalloc {

namespace {

// fcntl(F_SETLK or F_SETLKW) on the whole file, restarted when a signal interrupts it.
int lockWhole(int fd, int command) {
  struct flock whole {};
  whole.l_type = F_WRLCK;
  whole.l_whence = SEEK_SET;  // l_start = l_len = 0: the whole file
  int result;
  while ((result = ::fcntl(fd, command, &whole)) < 0 && errno == EINTR) {
  }
  return result;
}

}  // namespace

FileLock::FileLock(const std::string& path, const std::function<void()>& onWait) {
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (fd_ < 0) throw InputError(fmt::format("cannot open the lock file {}: {}", path, std::strerror(errno)));
  int result = lockWhole(fd_, F_SETLK);
  if (result < 0 && (errno == EACCES || errno == EAGAIN)) {
    if (onWait) onWait();
    result = lockWhole(fd_, F_SETLKW);
  }
  if (result < 0) {
    const int error = errno;
    ::close(fd_);
    throw InputError(fmt::format("cannot lock {}: {}", path, std::strerror(error)));
  }
}

FileLock::~FileLock() { ::close(fd_); }  // closing releases the process's record locks

}  // namespace misalloc
