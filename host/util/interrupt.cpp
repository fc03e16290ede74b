#include "util/interrupt.h"

#include <signal.h>

#include <csignal>

namespace pr {

namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void onInterrupt(int signal) {
  g_signal = signal;
}

}  // namespace

void installInterruptHandlers() {
  struct sigaction sa = {};
  sa.sa_handler = onInterrupt;
  sigemptyset(&sa.sa_mask);
  // SA_RESTART: a write in progress goes on instead of failing with EINTR.
  // SA_RESETHAND: a second Ctrl-C ends the process at once if the first is not acted on.
  sa.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  std::signal(SIGXFSZ, SIG_IGN);
}

int interruptSignal() {
  return g_signal;
}

void setInterruptSignal(int signal) {
  g_signal = signal;
}

}  // namespace pr
