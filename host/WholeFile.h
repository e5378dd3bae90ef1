#pragma once
// A cache entry's bytes, read whole.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace misalloc {

// The bytes of the regular file at `path`, in one read into a buffer of its size (a
// stream's copies would cost as much as the work a cache saves); none where it is
// absent, unreadable or not a regular file: a FIFO would block the open.
inline std::optional<std::string> readWholeFile(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return std::nullopt;
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"), std::fclose);
  const auto size = std::filesystem::file_size(path, error);
  if (!file || error) return std::nullopt;
  std::string bytes(size, '\0');
  if (std::fread(bytes.data(), 1, size, file.get()) != size) return std::nullopt;
  return bytes;
}

}  // namespace misalloc
