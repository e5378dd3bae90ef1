#include "AtomicFile.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "Error.h"

namespace misalloc {
namespace fs = std::filesystem;

void writeFileAtomically(const std::string& path, const std::string& content) {
  std::string tmp = fmt::format("{}.tmp{}", path, ::getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    out << content;
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      throw InputError(fmt::format("cannot write {}", path));
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw InputError(fmt::format("cannot write {}: {}", path, ec.message()));
  }
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
