// SIGINT/SIGTERM as a request to stop. While frames are rendered the handler only records the
// signal, and the frame loop and the integrators' sample passes poll it between launches, so no
// file is ever left half written and the device is never torn down mid-launch. Before that,
// while the scene loads and the kernels build, nothing is being written: the handler then ends
// the process at once with the usual line, whatever the loader is waiting on.
#pragma once

#include <string>

namespace pr {

// Installs the handlers for SIGINT and SIGTERM (a second signal of the same kind kills the
// process at once) and ignores SIGXFSZ, so a file-size limit is a write error, not a kill.
// The process starts in the loading phase: `what` names what is loaded in the line printed
// ("interrupted by SIGINT while loading WHAT: no frame rendered").
void installInterruptHandlers(const std::string& what = "");

// From here on a signal is recorded and polled (the frame loop cleans up and reports).
void endLoadingPhase();

// While one lives, a signal in the loading phase waits for it to end before the process exits,
// so a file being written is finished or removed first (files.cpp's atomic writes).
class DeferInterrupts {
 public:
  DeferInterrupts();
  ~DeferInterrupts();
  DeferInterrupts(const DeferInterrupts&) = delete;
  DeferInterrupts& operator=(const DeferInterrupts&) = delete;
};

// The signal that asked to stop (SIGINT, SIGTERM), or 0.
int interruptSignal();
inline bool interrupted() {
  return interruptSignal() != 0;
}

// Records `signal` as if it had arrived (tests), or clears the request with 0.
void setInterruptSignal(int signal);

}  // namespace pr
