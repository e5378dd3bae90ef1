#pragma once
// What SIGINT and SIGTERM do to a run that writes files: never leave a mix of old and
// new outputs. compare stops between runs and keeps what it has (InterruptionGuard);
// render and reference stop at once, except while they rename their outputs into
// place (exitOnInterrupt, CriticalSection).
#include <signal.h>

#include <functional>

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

// From now on SIGINT and SIGTERM end the process at once with exit code 128 + the
// signal, as their default action would, unless a CriticalSection is open: then they
// end it when the last one closes. A run that writes its outputs only inside a
// critical section (OutputSet::commit, the reference cache) then leaves all of them
// old or all of them new. SIGKILL cannot be caught: what it leaves behind is hidden
// temporaries, which the next run that writes there removes (AtomicFile.h).
void exitOnInterrupt();

// A library caller's own way to stop a run: the Python module's, whose Ctrl-C must raise
// KeyboardInterrupt and leave the interpreter usable, not end it. `check` is called
// between kernel launches (the stages of a render, the batches of a reference) and
// throws to stop the run there. None by default: the CLI's signals end the process.
void setInterruptionCheck(std::function<void()> check);
void checkInterruption();

class CriticalSection {
 public:
  CriticalSection();
  ~CriticalSection();
  CriticalSection(const CriticalSection&) = delete;
  CriticalSection& operator=(const CriticalSection&) = delete;
};

}  // namespace misalloc
