#pragma once
#include <chrono>
#include <cstdio>
#include <string>

namespace misalloc {

// Progress of a long run on stderr: a bar redrawn in place on a terminal, one plain
// line per step otherwise (logs, CI), each with the steps done and an estimate of the
// time left.
class ProgressMeter {
 public:
  ProgressMeter(int totalSteps, std::FILE* stream = stderr);
  ~ProgressMeter();

  // Marks one more step done; `label` says which.
  void step(const std::string& label);
  // A line of its own that the bar does not overwrite.
  void note(const std::string& message);

 private:
  std::string eta() const;
  void clearBar();

  int total_, done_ = 0;
  std::FILE* stream_;
  bool terminal_;
  bool barShown_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace misalloc
