// SIGINT/SIGTERM as a request to stop: the handler only records the signal, and the frame
// loop and the integrators' sample passes poll it between launches, so no file is ever left
// half written and the device is never torn down mid-launch.
#pragma once

namespace pr {

// Installs the handlers for SIGINT and SIGTERM (a second signal of the same kind kills the
// process at once) and ignores SIGXFSZ, so a file-size limit is a write error, not a kill.
void installInterruptHandlers();

// The signal that asked to stop (SIGINT, SIGTERM), or 0.
int interruptSignal();
inline bool interrupted() {
  return interruptSignal() != 0;
}

// Records `signal` as if it had arrived (tests), or clears the request with 0.
void setInterruptSignal(int signal);

}  // namespace pr
