#include "cl/context.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>

#include "cl/binary_cache.h"
#include "cl/kernel_sources.h"
#include "util/check.h"
#include "util/files.h"
#include "util/hash.h"

namespace pr {

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string buildLog(const cl::Program& program, const cl::Device& device) {
  std::string log;
  if (program.getBuildInfo(device, CL_PROGRAM_BUILD_LOG, &log) != CL_SUCCESS) return "";
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

void removeCacheFile(const std::string& file) {
  std::error_code ec;
  std::filesystem::remove(file, ec);
}

// The cached binary of `key` in `file`, or empty where there is none or it is not this key's
// whole binary (cl/binary_cache.h; such a file is removed).
std::string loadCachedBinary(const std::string& file, const std::string& key,
                             const std::string& secret) {
  std::string data;
  if (!readFile(file, &data)) return {};
  std::string binary = unpackCacheFile(data, key, secret);
  if (binary.empty()) removeCacheFile(file);
  return binary;
}

void storeCachedBinary(const std::string& file, const std::string& key, const std::string& binary,
                       const std::string& secret) {
  try {
    writeFileAtomic(file, packCacheFile(key, binary, secret));
  } catch (const RuntimeError&) {
    // An unwritable cache costs only build time next run.
  }
}

// The secret of the cache under `dir` (cl/binary_cache.h), or empty where the cache is off or
// cannot be trusted (said once per process and folder).
std::string cacheSecretFor(const std::string& dir) {
  if (dir.empty()) return {};
  static std::mutex mutex;
  static std::map<std::string, std::string> secrets;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = secrets.find(dir); it != secrets.end()) return it->second;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  std::string why;
  std::string secret = cacheSecret(dir + "/kernels", &why);
  if (secret.empty())
    std::fprintf(stderr, "note: the kernel cache is not used this run: %s\n", why.c_str());
  secrets[dir] = secret;
  return secret;
}

}  // namespace

std::string programCacheDir() {
  if (const char* dir = std::getenv("PATHREUSE_CACHE_DIR"); dir && *dir) {
    if (std::string(dir) == "off") return "";
    return dir;
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return std::string(xdg) + "/pathreuse";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.cache/pathreuse";
  return "";
}

Context::Context(const DeviceEntry& device)
    : device_(device), pocl_(device.platformVendor == "The pocl project") {
  cl_int err = CL_SUCCESS;
  context_ = cl::Context(device_.device, nullptr, nullptr, nullptr, &err);
  CL_CHECK(err);
  // Profiling gives per-stage kernel times for --stats; its cost is negligible.
  queue_ = cl::CommandQueue(context_, device_.device, CL_QUEUE_PROFILING_ENABLE, &err);
  CL_CHECK(err);
}

ProgramBuild Context::buildProgram(const std::string& mainFile, const std::string& options) {
  return buildProgramFromSource(expandKernelSource(mainFile), options, mainFile);
}

cl::Kernel Context::kernel(const std::string& file, const char* name, const std::string& options) {
  cl_int err = CL_SUCCESS;
  ProgramBuild build = buildProgram(file, options);
  cl::Kernel k(build.program, name, &err);
  if (err != CL_SUCCESS && build.fromCache) {
    // A cached binary that lacks the kernel is not this program's: built again from source.
    removeCacheFile(build.cacheFile);
    build = buildProgram(file, options);
    k = cl::Kernel(build.program, name, &err);
  }
  if (err != CL_SUCCESS)
    throw ClError(std::string("kernel ") + name + " of kernels/" + file, err, __FILE__, __LINE__);
  return k;
}

ProgramBuild Context::buildProgramFromSource(const std::string& source, const std::string& options,
                                             const std::string& label) {
  const auto t0 = std::chrono::steady_clock::now();
  // Argument info lets kargs::checkKernelArgs compare each kernel with its table.
  std::string fullOptions = "-cl-std=CL1.2 -cl-kernel-arg-info " + options;
  // Extra options for diagnosing a platform, e.g. -cl-opt-disable (part of the cache key).
  if (const char* extra = std::getenv("PATHREUSE_CL_OPTIONS"); extra && *extra)
    fullOptions += std::string(" ") + extra;
  // The file format is in the key too: another version's files have other names, not churn.
  const std::string key = Hash128()
                              .add(cacheFormatTag())
                              .add(source)
                              .add(fullOptions)
                              .add(device_.platformName)
                              .add(device_.name)
                              .add(device_.driverVersion)
                              .add(device_.deviceVersion)
                              .add(driverEnvironmentTag())
                              .hex();
  const std::string dir = programCacheDir();
  const std::string secret = cacheSecretFor(dir);
  const std::string file = secret.empty() ? "" : dir + "/kernels/" + key + ".bin";

  ProgramBuild out;
  out.cacheFile = file;
  if (!file.empty()) {
    const std::string binary = loadCachedBinary(file, key, secret);
    if (!binary.empty()) {
      cl::Program::Binaries bins{std::vector<unsigned char>(binary.begin(), binary.end())};
      std::vector<cl_int> status;
      cl_int err = CL_SUCCESS;
      cl::Program program(context_, {device_.device}, bins, &status, &err);
      if (err == CL_SUCCESS && program.build({device_.device}, fullOptions.c_str()) == CL_SUCCESS) {
        out.program = program;
        out.fromCache = true;
        out.seconds = secondsSince(t0);
        buildSeconds_[label + " (cached)"] += out.seconds;
        return out;
      }
      // A binary the driver refuses (driver updated in place, truncated file): rebuild.
      removeCacheFile(file);
    }
  }

  if (buildNotice_ && !noticeGiven_) {
    noticeGiven_ = true;
    std::fprintf(stderr, "compiling OpenCL kernels for %s (once for these options; %s)\n",
                 device_.name.c_str(),
                 file.empty() ? "the kernel cache is off"
                              : ("later runs load them from " + dir + "/kernels").c_str());
  }
  cl_int err = CL_SUCCESS;
  cl::Program program(context_, source, false, &err);
  CL_CHECK(err);
  err = program.build({device_.device}, fullOptions.c_str());
  if (err != CL_SUCCESS) {
    const std::string log = buildLog(program, device_.device);
    throw RuntimeError("building kernels/" + label + " for " + device_.name + " failed with " +
                       clErrorName(err) + "; build log:\n" + log);
  }
  if (!file.empty()) {
    std::vector<std::vector<unsigned char>> binaries;
    if (program.getInfo(CL_PROGRAM_BINARIES, &binaries) == CL_SUCCESS && binaries.size() == 1 &&
        !binaries[0].empty())
      storeCachedBinary(file, key, std::string(binaries[0].begin(), binaries[0].end()), secret);
  }
  out.program = program;
  out.seconds = secondsSince(t0);
  buildSeconds_[label] += out.seconds;
  return out;
}

cl::Buffer Context::allocate(const std::string& name, uint64_t bytes, cl_mem_flags flags) {
  if (bytes == 0) bytes = 16;  // zero-sized buffers are invalid; keep a valid handle
  if (bytes > device_.maxAllocBytes)
    throw RuntimeError("device out of memory: " + name + " needs " + formatBytes(bytes) +
                       " but the largest allocation " + device_.name + " allows is " +
                       formatBytes(device_.maxAllocBytes));
  // Some drivers allocate on first use; this names the buffer before a later launch fails.
  if (device_.globalMemBytes > 0 &&
      bytes > device_.globalMemBytes - std::min(bytesInUse_, device_.globalMemBytes))
    throw RuntimeError("device out of memory: " + name + " (" + formatBytes(bytes) +
                       ") does not fit beside the " + formatBytes(bytesInUse_) +
                       " already in use of " + formatBytes(device_.globalMemBytes) + " on " +
                       device_.name);
  cl_int err = CL_SUCCESS;
  cl::Buffer buffer(context_, flags, bytes, nullptr, &err);
  if (err == CL_MEM_OBJECT_ALLOCATION_FAILURE || err == CL_OUT_OF_RESOURCES ||
      err == CL_OUT_OF_HOST_MEMORY)
    throw RuntimeError("device out of memory: " + name + " (" + formatBytes(bytes) +
                       ") did not fit; " + formatBytes(bytesInUse_) + " already in use on " +
                       device_.name);
  CL_CHECK(err);
  bytesInUse_ += bytes;
  bytesByName_[name] += bytes;
  return buffer;
}

void Context::release(const std::string& name, uint64_t bytes) {
  bytesInUse_ -= std::min(bytes, bytesInUse_);
  auto it = bytesByName_.find(name);
  if (it == bytesByName_.end()) return;
  it->second -= std::min(bytes, it->second);
  if (it->second == 0) bytesByName_.erase(it);
}

void Context::zero(const cl::Buffer& buffer, uint64_t bytes) {
  if (bytes == 0) return;
  const cl_uint pattern = 0;
  if (bytes % sizeof pattern == 0) {
    CL_CHECK(queue_.enqueueFillBuffer(buffer, pattern, 0, bytes));
  } else {
    const cl_uchar bytePattern = 0;
    CL_CHECK(queue_.enqueueFillBuffer(buffer, bytePattern, 0, bytes));
  }
}

void Context::launch1D(const cl::Kernel& kernel, size_t first, size_t end, const char* stage,
                       StageTimer* timer) {
  if (end <= first) return;
  const size_t global = end - first;
  size_t local = 0;
  CL_CHECK(kernel.getWorkGroupInfo(device_.device, CL_KERNEL_WORK_GROUP_SIZE, &local));
  size_t preferred = 0;
  if (kernel.getWorkGroupInfo(device_.device, CL_KERNEL_PREFERRED_WORK_GROUP_SIZE_MULTIPLE,
                              &preferred) == CL_SUCCESS &&
      preferred > 0 && preferred <= local) {
    // A multiple of the preferred size, up to 256, keeps GPUs busy.
    size_t want = preferred;
    while (want * 2 <= local && want * 2 <= 256) want *= 2;
    local = want;
  }
  // PoCL keeps a private copy of a kernel's variables for each work-item of a group on its worker
  // thread's stack (8 MiB under Debian's default `ulimit -s`, 4 MiB at least: enumerateDevices):
  // at 256 items pt_resample needed 7.2-7.7 MiB, and a little more code in it overran into
  // another thread's stack. At 64 it needs 1.5-2 MiB and runs no slower
  // (tools/ci/pocl-stack-check.sh).
  if (pocl_) local = std::min<size_t>(local, 64);
  if (local == 0) local = 1;
  const size_t padded = (global + local - 1) / local * local;
  const size_t chunk = std::max(local, kMaxLaunchItems / local * local);
  for (size_t offset = 0; offset < padded; offset += chunk) {
    const size_t n = std::min(chunk, padded - offset);
    const cl_int err = queue_.enqueueNDRangeKernel(kernel, cl::NDRange(first + offset),
                                                   cl::NDRange(n), cl::NDRange(local), nullptr,
                                                   timer ? timer->next(stage) : nullptr);
    if (err != CL_SUCCESS)
      throw ClError(std::string("launch of ") + stage, err, __FILE__, __LINE__);
  }
}

void Context::finish() {
  CL_CHECK(queue_.finish());
}

}  // namespace pr
