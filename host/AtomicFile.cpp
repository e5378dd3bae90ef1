#include "AtomicFile.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>

#include "ContentHash.h"
#include "Error.h"
#include "Interruption.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

bool writeAll(int fd, const std::string& content) {
  for (size_t done = 0; done < content.size();) {
    ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

// The longest file name the folder takes (NAME_MAX of its file system).
size_t nameLimit(const fs::path& folder) {
  long limit = ::pathconf(folder.empty() ? "." : folder.c_str(), _PC_NAME_MAX);
  return limit > 0 ? size_t(limit) : 255;
}

bool processRuns(long pid) { return ::kill(pid_t(pid), 0) == 0 || errno != ESRCH; }

bool allDigits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// The PID in the name of a temporary of this host (temporaryName: ".NAME.tmp-HOST-PID-
// ATTEMPT"), or -1 for a name of another host, or of no temporary.
long temporaryOwner(const std::string& name) {
  const size_t tag = name.rfind(".tmp-");
  if (name.empty() || name[0] != '.' || tag == std::string::npos || tag == 0) return -1;
  const std::string rest = name.substr(tag + 5), host = hostTag() + "-";
  if (rest.compare(0, host.size(), host) != 0) return -1;
  const std::string pidAndAttempt = rest.substr(host.size());
  const size_t dash = pidAndAttempt.find('-');
  if (dash == std::string::npos || !allDigits(pidAndAttempt.substr(0, dash)) ||
      !allDigits(pidAndAttempt.substr(dash + 1)))
    return -1;
  return dash > 9 ? -1 : std::stol(pidAndAttempt.substr(0, dash));
}

}  // namespace

const std::string& hostTag() {
  static const std::string tag = [] {
    char host[HOST_NAME_MAX + 1] = {};
    ::gethostname(host, sizeof host - 1);
    std::error_code ec;
    ContentHash h;
    h.add(std::string(host));
    h.add(fs::read_symlink("/proc/self/ns/pid", ec).string());  // "pid:[INODE]": the namespace
    return fmt::format("{:012x}", h.h >> 16);
  }();
  return tag;
}

std::string temporaryName(const std::string& path, int attempt) {
  const fs::path p(path);
  const std::string name = p.filename().string();
  const std::string suffix = fmt::format(".tmp-{}-{}-{}", hostTag(), ::getpid(), attempt);
  const size_t limit = nameLimit(p.parent_path());
  std::string stem = name;
  if (1 + stem.size() + suffix.size() > limit) {
    // Keep a prefix to recognise it by and a hash of the whole name to tell apart
    // targets that share the prefix.
    const std::string hash = fmt::format("~{:016x}", std::hash<std::string>{}(name));
    stem = name.substr(0, limit - 1 - suffix.size() - hash.size()) + hash;
  }
  return (p.parent_path() / ("." + stem + suffix)).string();
}

void removeStaleTemporaries(const std::string& folder) {
  static std::mutex mutex;
  static std::set<std::string> cleaned;
  std::error_code ec;
  const fs::path dir = folder.empty() ? fs::path(".") : fs::path(folder);
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (!cleaned.insert(fs::absolute(dir, ec).lexically_normal().string()).second) return;
  }
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const long pid = temporaryOwner(it->path().filename().string());
    struct stat info {};
    if (pid < 0 || ::lstat(it->path().c_str(), &info) != 0) continue;
    if (info.st_uid != ::geteuid() || pid == long(::getpid()) || processRuns(pid)) continue;
    std::error_code ignored;
    fs::remove_all(it->path(), ignored);
  }
}

std::string writeTemporaryBeside(const std::string& path, const std::string& content) {
  removeStaleTemporaries(fs::path(path).parent_path().string());
  for (int attempt = 0;; ++attempt) {
    std::string tmp = temporaryName(path, attempt);
    // 0666 and the umask, as for any new file; O_EXCL: an existing file is never touched.
    int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno == EEXIST) continue;
    if (fd < 0) throw InputError(fmt::format("cannot write {}: {}", path, std::strerror(errno)));
    bool written = writeAll(fd, content);
    int error = errno;
    if (::close(fd) != 0 && written) {
      written = false;
      error = errno;
    }
    if (!written) {
      std::remove(tmp.c_str());
      throw InputError(fmt::format("cannot write {}: {}", path, std::strerror(error)));
    }
    return tmp;
  }
}

void renameIntoPlace(const std::string& temporary, const std::string& path) {
  std::error_code ec;
  fs::rename(temporary, path, ec);
  if (ec) {
    std::remove(temporary.c_str());
    throw InputError(fmt::format("cannot write {}: {}", path, ec.message()));
  }
}

void writeFileAtomically(const std::string& path, const std::string& content) {
  const std::string temporary = writeTemporaryBeside(path, content);
  CriticalSection renaming;
  renameIntoPlace(temporary, path);
}

void checkWritableOutput(const std::string& path, const std::string& option) {
  if (path.empty()) throw InputError(fmt::format("{}: an empty path", option));
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir))
    throw InputError(fmt::format("{} {}: folder {} does not exist", option, path, dir.string()));
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(fmt::format("{} {}: folder {} is not writable", option, path, dir.string()));
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (fs::is_directory(status)) throw InputError(fmt::format("{} {}: is a folder", option, path));
  if (fs::exists(status) && !fs::is_regular_file(status))
    throw InputError(fmt::format(
        "{} {}: is not a regular file (a device, FIFO or socket); outputs are written beside their target and "
        "renamed over it, which would replace it: give a regular file's path",
        option, path));
}

}  // namespace misalloc
