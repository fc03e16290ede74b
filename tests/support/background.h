// The renderer running in the background (for signals sent while it works), its stderr going
// to a file.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace pr::test {

class Background {
 public:
  // Runs the pathreuse binary with `args`; stderr goes to dir/stderr. `env` entries
  // ("NAME=value") are added to this process's environment for the child.
  Background(const std::vector<std::string>& args, const std::string& dir,
             const std::vector<std::string>& env = {});
  ~Background();
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;

  bool started() const { return pid_ > 0; }
  void signal(int sig);
  std::string err() const;

  // Waits until `ready` holds, up to `seconds`; false when the process ended or time ran out.
  template <class F>
  bool waitUntil(F ready, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (ready()) return true;
      if (poll()) return ready();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  // The exit code (128 + signal when killed), or -1 when it has not ended within `seconds`.
  int wait(double seconds);

 private:
  bool poll();  // true once the process has ended

  std::string errFile_;
  pid_t pid_ = -1;
  int status_ = 0;
  bool exited_ = false;
};

}  // namespace pr::test
