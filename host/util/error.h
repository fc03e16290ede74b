// Error types and the exit codes they map to (docs/design.md section 1).
#pragma once

#include <stdexcept>
#include <string>

namespace pr {

enum ExitCode : int { kExitOk = 0, kExitRuntime = 1, kExitBadInput = 2 };

// Bad input or bad usage (a broken scene, an unknown option value): exit code 2.
// The message already names the file or option: "FILE: what is wrong (which object)".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A runtime or device failure: exit code 1.
class RuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pr
