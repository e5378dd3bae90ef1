#pragma once
// Runs the misalloc binary as a user would, and a scratch folder per test process.
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <string>

#include "TestBinary.h"

namespace misalloc::test {

struct CommandResult {
  int exitCode;
  std::string output;  // stdout and stderr
};

inline CommandResult runMisalloc(const std::string& args, const std::string& environment = "") {
  std::string command = fmt::format("{} {} {} 2>&1", environment, misallocBinary(), args);
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string output;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) output.append(buffer.data(), n);
  int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& name = "cli")
      : path(std::filesystem::temp_directory_path() / fmt::format("misalloc_{}_{}", name, ::getpid())) {
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
};

}  // namespace misalloc::test
