#include "Interruption.h"

#include <pthread.h>
#include <unistd.h>

#include <atomic>
#include <ctime>
#include <initializer_list>

namespace misalloc {
namespace {

// Lock-free atomics: the handler may run on any thread, between any two instructions.
std::atomic<int> openSections{0}, deferredSignal{0};
static_assert(std::atomic<int>::is_always_lock_free);

void exitNowOrDefer(int signal) {
  if (openSections.load() > 0)
    deferredSignal.store(signal);
  else
    _exit(128 + signal);  // async-signal-safe, unlike exit()
}

}  // namespace

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

void exitOnInterrupt() {
  struct sigaction action {};
  action.sa_handler = exitNowOrDefer;
  sigemptyset(&action.sa_mask);
  for (int signal : {SIGINT, SIGTERM}) sigaction(signal, &action, nullptr);
}

namespace {
std::function<void()> interruptionCheck;
}  // namespace

void setInterruptionCheck(std::function<void()> check) { interruptionCheck = std::move(check); }

void checkInterruption() {
  if (interruptionCheck) interruptionCheck();
}

CriticalSection::CriticalSection() { openSections.fetch_add(1); }

CriticalSection::~CriticalSection() {
  if (openSections.fetch_sub(1) == 1 && deferredSignal.load() != 0) _exit(128 + deferredSignal.load());
}

}  // namespace misalloc
