// Several OpenCL devices rendering each frame together. Every device has its own RenderSession
// (device scene, arena, film) of the same scene and options, and renders a range of whole rows;
// the ranges tile the image, so each pixel is computed by exactly one device as a single device
// would compute it. Path reuse's light paths (invalidation and light tracing of every slot) are
// replicated on every device: the same slots and keys give the same light paths, so no arena
// moves between devices. The devices render concurrently, one host thread each; the rows of a
// frame are split in proportion to each device's throughput in the previous frame.
//
// With --resample a pixel's paths are resampled with its neighbours' and with the previous
// frame's paths anywhere in the image, which a device holding some rows does not have. There the
// devices split the sample passes instead: each renders every pixel in a range of passes, and the
// films' sums are added in device order before the mean. Pass s of a frame resamples with pass s
// of the previous one, whose chain of reservoirs the device holding pass s keeps (only its own
// passes' chains). The first frame splits the passes evenly; after each frame the split follows
// the devices' passes per second where that shortens the frame by over 15%
// (balancePasses), and a pass that changes device takes its chain along. Every sample is then
// the one a single device computes. So is the frame, bit for bit, where every device after the
// first holds one pass (one device's sum in its order: the first's sum of passes [0, k), then
// pass k); otherwise the sums' grouping differs in float rounding alone.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cl/device.h"
#include "io/image.h"
#include "render/integrator.h"
#include "render/options.h"
#include "render/session.h"
#include "scene/scene.h"

namespace pr {

// One device's part of a frame.
struct DeviceFrame {
  int index = 0;  // the device's index in `pathreuse devices`
  std::string name;
  int rowBegin = 0, rowEnd = 0;
  int passBegin = 0, passEnd = 0;  // its sample passes
  double share = 0.0;              // of the frame's pixel samples
  double wallSeconds = 0.0;        // its thread: scene update, kernels, reading its rows
  FrameStats stats;
};

// `height` rows split in proportion to `weights` (positive), largest remainders first; while
// there are as many rows as weights, every part gets at least one. Returns the rows per part.
std::vector<int> splitRows(int height, const std::vector<double>& weights);

// The next frame's split of the sample passes, given each device's `passes` and the `seconds` it
// took over them: in proportion to passes per second (every device at least one pass while there
// are enough), where that makes the slowest device's predicted time over 15% shorter; else
// `passes`, also where some device rendered none or took no time.
std::vector<int> balancePasses(const std::vector<int>& passes, const std::vector<double>& seconds);

class MultiDeviceSession {
 public:
  // Builds one RenderSession per device (concurrently); `scene` must outlive this. Throws as
  // RenderSession does (the first device's error where several fail).
  MultiDeviceSession(const Scene& scene, const std::vector<const DeviceEntry*>& devices,
                     const RenderOptions& options);

  // Renders frame f on every device and merges the rows. `total` sums the devices' stats
  // (counters of the replicated light paths are every device's and counted once); `parts`
  // gets each device's. Then splits the next frame's rows by the measured throughput.
  Image renderFrame(int64_t frame, FrameStats* total, std::vector<DeviceFrame>* parts);

  size_t deviceCount() const { return sessions_.size(); }
  RenderSession& session(size_t i) { return *sessions_[i]; }
  const DeviceEntry& device(size_t i) const { return *devices_[i]; }
  int width() const { return sessions_[0]->width(); }
  int height() const { return sessions_[0]->height(); }
  FrameRange frameRange() const { return sessions_[0]->frameRange(); }
  // Rows of each device for the next frame.
  const std::vector<int>& rows() const { return rows_; }
  // With --resample and several devices: the sample passes of each for the next frame; else
  // empty.
  const std::vector<int>& passes() const { return passes_; }
  // Sets that split (as many parts as devices, summing to spp); the chains of the passes that
  // change device move with them.
  void setPassSplit(const std::vector<int>& passes);

 private:
  void setRows(const std::vector<int>& rows);
  // Frame f with the passes split (--resample): every device's film summed into `img`.
  void renderPasses(int64_t frame, Image* img, std::vector<DeviceFrame>* parts);

  std::vector<const DeviceEntry*> devices_;
  std::vector<std::unique_ptr<RenderSession>> sessions_;
  std::vector<int> rows_;
  std::vector<double> throughput_;  // rows per second of the last frame each device rendered
  std::vector<int> passes_;         // with --resample and several devices, passes per device
  int spp_ = 0;                     // samples per pixel of a frame
  bool denoise_ = false;            // --denoise
};

}  // namespace pr
