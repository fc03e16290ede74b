#include "util/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>

namespace pr {

namespace {

volatile std::sig_atomic_t g_signal = 0;
volatile std::sig_atomic_t g_loading = 0;
std::atomic<int> g_deferring{0};  // DeferInterrupts alive (any thread)
static_assert(std::atomic<int>::is_always_lock_free, "read in a signal handler");
// The lines the handler writes while loading, composed beforehand: a handler may only call
// async-signal-safe functions (write, _exit).
char g_intLine[512];
char g_termLine[512];

void compose(char* out, size_t size, const char* sig, const std::string& what) {
  std::string line = std::string("interrupted by ") + sig + " while loading";
  if (!what.empty()) line += " " + what;
  line += ": no frame rendered\n";
  if (line.size() >= size) line = std::string("interrupted by ") + sig + ": no frame rendered\n";
  std::memcpy(out, line.c_str(), line.size() + 1);
}

[[noreturn]] void exitInterrupted(int signal) {
  const char* line = signal == SIGTERM ? g_termLine : g_intLine;
  ssize_t ignored = ::write(STDERR_FILENO, line, std::strlen(line));
  (void)ignored;
  ::_exit(128 + signal);
}

extern "C" void onInterrupt(int signal) {
  g_signal = signal;
  if (g_loading && !g_deferring) exitInterrupted(signal);
}

}  // namespace

void installInterruptHandlers(const std::string& what) {
  compose(g_intLine, sizeof g_intLine, "SIGINT", what);
  compose(g_termLine, sizeof g_termLine, "SIGTERM", what);
  g_loading = 1;
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

DeferInterrupts::DeferInterrupts() {
  ++g_deferring;
}

DeferInterrupts::~DeferInterrupts() {
  if (--g_deferring == 0 && g_loading && g_signal) exitInterrupted(g_signal);
}

void endLoadingPhase() {
  g_loading = 0;
}

int interruptSignal() {
  return g_signal;
}

void setInterruptSignal(int signal) {
  g_signal = signal;
}

}  // namespace pr
