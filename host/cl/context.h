// One chosen OpenCL device with its context and in-order queue; builds programs from the
// kernel sources (cached on disk) and allocates buffers with their sizes checked and counted.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>

#include "cl/cl.h"
#include "cl/device.h"
#include "cl/stage_timer.h"

namespace pr {

struct ProgramBuild {
  cl::Program program;
  bool fromCache = false;  // the binary came from the on-disk cache
  double seconds = 0.0;    // wall time of the build (or cache load)
  std::string cacheFile;   // empty when caching is off or failed
};

// Folder for cached program binaries: $PATHREUSE_CACHE_DIR, else $XDG_CACHE_HOME/pathreuse,
// else ~/.cache/pathreuse; empty when none can be determined. The value "off" disables it.
std::string programCacheDir();

class Context {
 public:
  explicit Context(const DeviceEntry& device);

  const DeviceEntry& device() const { return device_; }
  cl::Context& context() { return context_; }
  cl::CommandQueue& queue() { return queue_; }

  // Builds kernels/<mainFile> with `options` (e.g. "-DMAX_DEPTH=8"). A failed build throws
  // RuntimeError carrying the full build log. Binaries are cached by a hash of the expanded
  // source, the options, the device name and the driver version; a corrupt entry is rebuilt.
  ProgramBuild buildProgram(const std::string& mainFile, const std::string& options = "");

  // The kernel `name` of kernels/<file> built with `options`.
  cl::Kernel kernel(const std::string& file, const char* name, const std::string& options = "");

  // Same, from a source string (for tests and generated code).
  ProgramBuild buildProgramFromSource(const std::string& source, const std::string& options,
                                      const std::string& label);

  // A device buffer of `bytes`, checked against the device's max allocation; `name` is used in
  // errors ("device out of memory: light vertex arena (1.2 GiB) ..."). Counted in bytesInUse()
  // and, under its name, in bytesByName().
  cl::Buffer allocate(const std::string& name, uint64_t bytes,
                      cl_mem_flags flags = CL_MEM_READ_WRITE);
  // Releases the count of a buffer made by allocate() under `name` (the buffer itself is
  // reference counted).
  void release(const std::string& name, uint64_t bytes);
  uint64_t bytesInUse() const { return bytesInUse_; }
  // The bytes in use by buffer name (buffers of one name summed), for --stats.
  const std::map<std::string, uint64_t>& bytesByName() const { return bytesByName_; }

  // With a notice, the first build from source (not from the cache) prints one line on stderr:
  // a GPU's compiler may take minutes over the reuse kernels.
  void setBuildNotice(bool on) { buildNotice_ = on; }
  // The programs built or loaded from the cache since the last call: "file" or "file (cached)"
  // with its seconds, for --stats.
  std::map<std::string, double> takeBuildSeconds() { return std::exchange(buildSeconds_, {}); }

  // Fills a buffer with zero bytes (PoCL does not zero new buffers).
  void zero(const cl::Buffer& buffer, uint64_t bytes);

  // A 1-D launch of `global` work-items, padded to a multiple of the work-group size that the
  // device reports for the kernel; kernels guard with their own count argument. Large launches
  // are split into chunks of kMaxLaunchItems (with a global offset) so that no single launch
  // runs long enough to trip a GPU watchdog. With a timer, each chunk's time counts for `stage`.
  void launch1D(const cl::Kernel& kernel, size_t global, const char* stage,
                StageTimer* timer = nullptr) {
    launch1D(kernel, 0, global, stage, timer);
  }
  // Work-items [first, end) only: get_global_id(0) runs over the global indices (a device's
  // part of an image keeps each pixel's index); kernels guard with end as their count.
  void launch1D(const cl::Kernel& kernel, size_t first, size_t end, const char* stage,
                StageTimer* timer = nullptr);
  static constexpr size_t kMaxLaunchItems = size_t(1) << 18;

  void finish();

 private:
  DeviceEntry device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  uint64_t bytesInUse_ = 0;
  std::map<std::string, uint64_t> bytesByName_;
  bool buildNotice_ = false;
  bool pocl_ = false;  // launch1D's groups: PoCL's worker stacks hold them
  bool noticeGiven_ = false;
  std::map<std::string, double> buildSeconds_;
};

}  // namespace pr
