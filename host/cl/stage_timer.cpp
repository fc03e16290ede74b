#include "cl/stage_timer.h"

namespace pr {

cl::Event* StageTimer::next(const std::string& stage) {
  events_.emplace_back(stage, cl::Event());
  return &events_.back().second;
}

std::map<std::string, double> StageTimer::collect() {
  std::map<std::string, double> out;
  for (auto& [stage, ev] : events_) {
    if (!ev()) continue;
    cl_ulong start = 0, end = 0;
    if (ev.wait() != CL_SUCCESS) continue;
    if (ev.getProfilingInfo(CL_PROFILING_COMMAND_START, &start) != CL_SUCCESS ||
        ev.getProfilingInfo(CL_PROFILING_COMMAND_END, &end) != CL_SUCCESS)
      continue;
    out[stage] += end > start ? double(end - start) * 1e-9 : 0.0;
  }
  events_.clear();
  return out;
}

}  // namespace pr
