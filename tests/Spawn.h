#pragma once
// misalloc in processes of their own, for tests that run several at once or signal them.
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <string>
#include <thread>

#include "TestBinary.h"

namespace misalloc::test {

// misalloc with `args` in a process of its own, its stdout and stderr to `log`.
inline pid_t spawnMisalloc(const std::string& args, const std::string& environment = "",
                           const std::string& log = "/dev/null") {
  const std::string command = fmt::format("exec env {} {} {} >'{}' 2>&1", environment, misallocBinary(), args, log);
  pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), (char*)nullptr);
    _exit(127);
  }
  return pid;
}

// Waits (at most a minute) until `ready` holds; false if it never did.
template <typename Predicate>
bool waitFor(Predicate ready) {
  for (auto start = std::chrono::steady_clock::now();
       std::chrono::steady_clock::now() - start < std::chrono::minutes(1);) {
    if (ready()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

inline int waitStatus(pid_t pid) {
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  return status;
}

}  // namespace misalloc::test
