// Per-stage kernel times of one frame, from the queue's profiling events.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cl/cl.h"

namespace pr {

class StageTimer {
 public:
  // An event to pass to a launch; its time is added to `stage` when collect() runs.
  cl::Event* next(const std::string& stage);
  // Seconds per stage of the events so far (waits for them); clears the list.
  std::map<std::string, double> collect();

 private:
  std::vector<std::pair<std::string, cl::Event>> events_;
};

}  // namespace pr
