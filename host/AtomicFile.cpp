#include "AtomicFile.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "Error.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

// A hidden name beside `path` with ".tmp" in it, so that leftovers of a killed run are
// easy to recognise; `attempt` makes it unique when an earlier one exists.
std::string temporaryName(const std::string& path, int attempt) {
  fs::path p(path);
  return (p.parent_path() / fmt::format(".{}.tmp-{}-{}", p.filename().string(), ::getpid(), attempt)).string();
}

bool writeAll(int fd, const std::string& content) {
  for (size_t done = 0; done < content.size();) {
    ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

}  // namespace

std::string writeTemporaryBeside(const std::string& path, const std::string& content) {
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
  renameIntoPlace(writeTemporaryBeside(path, content), path);
}

void checkWritableOutput(const std::string& path, const std::string& option) {
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir))
    throw InputError(fmt::format("{} {}: folder {} does not exist", option, path, dir.string()));
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(fmt::format("{} {}: folder {} is not writable", option, path, dir.string()));
  if (fs::is_directory(path)) throw InputError(fmt::format("{} {}: is a folder", option, path));
}

}  // namespace misalloc
