#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace pr {

// Runs task(0 .. count - 1) on every core: each task touches only what its index names, so the
// results do not depend on which thread ran which.
template <class Task>
void parallelFor(int count, Task task) {
  std::atomic<int> next{0};
  std::vector<std::thread> workers;
  const unsigned threads =
      std::min(std::max(1u, std::thread::hardware_concurrency()), unsigned(std::max(count, 1)));
  for (unsigned w = 0; w < threads; ++w)
    workers.emplace_back([&] {
      for (int j; (j = next++) < count;) task(j);
    });
  for (std::thread& w : workers) w.join();
}

}  // namespace pr
