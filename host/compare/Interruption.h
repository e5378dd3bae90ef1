#pragma once
#include <signal.h>

namespace misalloc {

// While alive, SIGINT and SIGTERM are blocked in this thread and in every thread
// created after it (PoCL's and OpenMP's workers), so they stay pending until a long
// loop polls for them between steps and stops with every file it wrote complete.
// Blocking, rather than a handler, also keeps them away from LLVM, whose own handler
// would delete the temporary files of a kernel compilation in flight (PoCL compiles
// through LLVM in-process). Create it before any other thread starts.
class InterruptionGuard {
 public:
  InterruptionGuard();
  ~InterruptionGuard();
  InterruptionGuard(const InterruptionGuard&) = delete;
  InterruptionGuard& operator=(const InterruptionGuard&) = delete;

  // True once SIGINT or SIGTERM has arrived.
  bool requested();

 private:
  sigset_t signals_, previousMask_;
  bool requested_ = false;
};

}  // namespace misalloc
