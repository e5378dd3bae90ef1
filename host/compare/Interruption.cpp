#include "compare/Interruption.h"

#include <pthread.h>

#include <ctime>

namespace misalloc {

InterruptionGuard::InterruptionGuard() {
  sigemptyset(&signals_);
  sigaddset(&signals_, SIGINT);
  sigaddset(&signals_, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals_, &previousMask_);
}

InterruptionGuard::~InterruptionGuard() {
  // Consume what is pending, so that unblocking delivers nothing.
  const timespec now{0, 0};
  while (sigtimedwait(&signals_, nullptr, &now) > 0) {
  }
  pthread_sigmask(SIG_SETMASK, &previousMask_, nullptr);
}

bool InterruptionGuard::requested() {
  const timespec now{0, 0};
  if (!requested_ && sigtimedwait(&signals_, nullptr, &now) > 0) requested_ = true;
  return requested_;
}

}  // namespace misalloc
