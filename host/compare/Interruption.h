#pragma once

namespace misalloc {

// While alive, SIGINT and SIGTERM only raise a flag that long loops poll between
// steps, so that they stop with every file they wrote complete. A second signal
// takes the default action: a user who insists gets an immediate exit (files are
// still never half-written, host/AtomicFile.h).
class InterruptionGuard {
 public:
  InterruptionGuard();
  ~InterruptionGuard();
  InterruptionGuard(const InterruptionGuard&) = delete;
  InterruptionGuard& operator=(const InterruptionGuard&) = delete;

  static bool requested();
};

}  // namespace misalloc
