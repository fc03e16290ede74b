// What every rendering mode provides to the frame loop.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <set>
#include <string>

#include "shared/camera.h"

namespace pr {

// A frame number as the kernels' 32-bit RNG key: the frame itself below 2^32, its halves
// folded above.
inline uint32_t rngFrameKey(int64_t frame) {
  return static_cast<uint32_t>(static_cast<uint64_t>(frame) ^ (static_cast<uint64_t>(frame) >> 32));
}

struct FrameStats {
  int64_t frame = 0;
  double wallSeconds = 0.0;
  std::map<std::string, double> stageSeconds;  // kernel time per stage
  // Host time: "scene" (animation, deformation, BVH builds, uploads), "deform" (its part
  // deforming meshes and rebuilding their BVHs).
  std::map<std::string, double> hostSeconds;
  std::map<std::string, uint64_t> rays;      // rays by kind
  std::map<std::string, uint64_t> counters;  // mode-specific counts (slots reused, ...)
  // Kernel programs built (or loaded from the cache, "(cached)") since the last frame, with
  // their seconds: the first frame's line shows what a cold start costs.
  std::map<std::string, double> buildSeconds;
  // Those of `counters` that describe the light paths, which every device of a several-device
  // render holds alike (render/multi_device.h counts them once).
  std::set<std::string> lightPathCounters;
  uint64_t deviceBytes = 0;
  std::map<std::string, uint64_t> deviceBuffers;  // deviceBytes by buffer name
  uint64_t badSamples = 0;
  uint32_t motionSteps = 1;  // under --shutter, the times the scene was placed at (1: none)
  int passes = 0;  // sample passes rendered (each pixel's samples; fewer under --time-limit)
  // Under --noise-threshold, the mean and maximum of the pixels' samples (-1: `passes` each).
  double sppMean = -1.0;
  int sppMax = 0;
};

// State that an integrator carries from one frame to the next (--resample's reservoirs, one
// chain per sample pass: render/path_tracer.h). --resume keeps it in a file beside each frame
// (render/history_format.h) and several devices move a pass's chain with the pass
// (render/multi_device.h).
class FrameHistory {
 public:
  virtual ~FrameHistory() = default;
  // Whether the last frame left a whole history, and its bytes under `key` (everything else it
  // depends on: scene, options).
  virtual bool hasHistory() const = 0;
  virtual std::string writeHistory(const std::string& key) = 0;
  // Whether `data` is a whole history of `key`, this device's chains and film rows and frame
  // `frame` (the frame that wrote it), every record in range; applyHistory then loads it. The
  // caller sets the scene to that frame's time before checking (the records name its lights).
  virtual bool checkHistory(const std::string& data, const std::string& key,
                            int64_t frame) const = 0;
  virtual void applyHistory(const std::string& data) = 0;
  // Passes [0, chains) keep a chain, on whichever device renders them: its records over the
  // film's rows, and writing them where the pass now is.
  virtual int chains() const = 0;
  virtual std::string chain(int pass) = 0;
  virtual void setChain(int pass, const std::string& records) = 0;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  // What it carries between frames; null where each frame stands alone.
  virtual FrameHistory* history() { return nullptr; }
  // What the run's first line says of it besides mode and devices ("" where nothing).
  virtual std::string describe() const { return ""; }
  // Renders frame `frame` (the scene already set to its time) into the film. Returns early,
  // leaving the film partial, once pr::interrupted(); the caller then drops the frame.
  virtual void renderFrame(int64_t frame, const dev::CameraParams& camera, FrameStats* stats) = 0;
  virtual uint64_t deviceBytes() const = 0;
  // Sample passes [begin, end) of each frame are rendered (default: all, end -1 for spp):
  // several devices split a frame's passes rather than its rows with --resample
  // (render/multi_device.h).
  virtual void setPasses(int begin, int end) {
    passBegin_ = begin;
    passEnd_ = end;
  }

  // --time-limit: a frame renders no pass after the one during which `seconds`, counted from
  // the start of renderFrame, ran out (at least one pass); 0: none.
  void setTimeLimit(double seconds) { timeLimit_ = seconds; }

 protected:
  using Clock = std::chrono::steady_clock;
  int passEnd(int spp) const { return passEnd_ < 0 ? spp : passEnd_; }
  // Whether the frame begun at `start` is out of time.
  bool outOfTime(Clock::time_point start) const {
    return timeLimit_ > 0.0 &&
           std::chrono::duration<double>(Clock::now() - start).count() >= timeLimit_;
  }
  int passBegin_ = 0, passEnd_ = -1;
  double timeLimit_ = 0.0;
};

}  // namespace pr
