#include "compare/Interruption.h"

#include <csignal>

namespace misalloc {
namespace {

volatile std::sig_atomic_t gRequested = 0;

extern "C" void onInterrupt(int signal) {
  gRequested = 1;
  std::signal(signal, SIG_DFL);
}

}  // namespace

InterruptionGuard::InterruptionGuard() {
  gRequested = 0;
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
}

InterruptionGuard::~InterruptionGuard() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

bool InterruptionGuard::requested() { return gRequested != 0; }

}  // namespace misalloc
