#include "cl/device.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include <pthread.h>

#include <nlohmann/json.hpp>

#include "util/files.h"

namespace pr {

namespace {

std::string trimmed(std::string s) {
  // Drivers pad some strings with spaces or NULs.
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back()))))
    s.pop_back();
  size_t b = 0;
  while (b < s.size() && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  return s.substr(b);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

template <cl_int Name>
auto deviceInfo(const cl::Device& d) {
  cl_int err = CL_SUCCESS;
  auto value = d.getInfo<Name>(&err);
  CL_CHECK(err);
  return value;
}

bool parseUnsigned(const std::string& s, int* out) {
  if (s.empty() || s.size() > 6) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  *out = std::stoi(s);
  return true;
}

}  // namespace

std::string deviceTypeName(cl_device_type type) {
  if (type & CL_DEVICE_TYPE_GPU) return "GPU";
  if (type & CL_DEVICE_TYPE_CPU) return "CPU";
  if (type & CL_DEVICE_TYPE_ACCELERATOR) return "ACCELERATOR";
  return "OTHER";
}

namespace {

// PoCL runs a work-group on one of its worker threads and keeps each work-item's private
// variables on that thread's stack (Context::launch1D). Its threads take the process's default
// stack size: `ulimit -s`, or 2 MiB where that is unlimited, which the reuse kernels outgrew
// (docs/experiments/pocl-work-group-method.md). Raised to kWorkerStackBytes where smaller, before
// the first OpenCL call creates them.
constexpr size_t kWorkerStackBytes = size_t(4) << 20;

void raiseDefaultThreadStack() {
  pthread_attr_t attr;
  if (pthread_getattr_default_np(&attr) != 0) return;
  size_t size = 0;
  if (pthread_attr_getstacksize(&attr, &size) == 0 && size < kWorkerStackBytes &&
      pthread_attr_setstacksize(&attr, kWorkerStackBytes) == 0)
    pthread_setattr_default_np(&attr);
  pthread_attr_destroy(&attr);
}

}  // namespace

std::vector<DeviceEntry> enumerateDevices() {
  raiseDefaultThreadStack();
  // PoCL compiles a work-group function for each launch's local size, global offset (zero or
  // not) and grid width (below 65,535 or not) the first time it meets them, outside any
  // program binary: a new image size cost up to a minute of compiling (the demo: 42 s at a
  // first size, 33 s at a second, with PoCL's own cache empty). Its generic functions, which
  // the program binaries in our kernel cache hold, ran no slower here
  // (docs/experiments/pocl-work-group-specialisation.md). Before the first OpenCL call, and where
  // the user has not chosen.
  setenv("POCL_WORK_GROUP_SPECIALIZATION", "0", 0);
  // PoCL 3.1's default work-group method, loopvec, vectorises the loop over a group's work-items
  // and compiled the traversal into code that missed hits (found with one traversal for blended
  // and sharp meshes: 32 shadow rays of 5,604 on the sweep scene, which ones depending on the
  // worker thread). Its plain work-item loops compile those kernels right, and faster
  // (docs/experiments/pocl-work-group-method.md).
  setenv("POCL_WORK_GROUP_METHOD", "loops", 0);
  std::vector<cl::Platform> platforms;
  cl_int err = cl::Platform::get(&platforms);
  // The ICD loader reports "no platform" as CL_PLATFORM_NOT_FOUND_KHR: an empty list, not a
  // failure.
  if (err == CL_PLATFORM_NOT_FOUND_KHR || err == CL_DEVICE_NOT_FOUND) return {};
  CL_CHECK(err);

  std::vector<DeviceEntry> out;
  for (size_t p = 0; p < platforms.size(); ++p) {
    std::vector<cl::Device> devices;
    err = platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
    if (err == CL_DEVICE_NOT_FOUND) continue;
    CL_CHECK(err);
    std::string platformName, platformVendor;
    CL_CHECK(platforms[p].getInfo(CL_PLATFORM_NAME, &platformName));
    CL_CHECK(platforms[p].getInfo(CL_PLATFORM_VENDOR, &platformVendor));
    for (size_t d = 0; d < devices.size(); ++d) {
      DeviceEntry e;
      e.index = static_cast<int>(out.size());
      e.platformIndex = static_cast<int>(p);
      e.deviceIndex = static_cast<int>(d);
      e.platform = platforms[p];
      e.device = devices[d];
      e.platformName = trimmed(platformName);
      e.platformVendor = trimmed(platformVendor);
      e.name = trimmed(deviceInfo<CL_DEVICE_NAME>(devices[d]));
      e.vendor = trimmed(deviceInfo<CL_DEVICE_VENDOR>(devices[d]));
      e.driverVersion = trimmed(deviceInfo<CL_DRIVER_VERSION>(devices[d]));
      e.deviceVersion = trimmed(deviceInfo<CL_DEVICE_VERSION>(devices[d]));
      e.openclCVersion = trimmed(deviceInfo<CL_DEVICE_OPENCL_C_VERSION>(devices[d]));
      e.type = deviceInfo<CL_DEVICE_TYPE>(devices[d]);
      e.computeUnits = deviceInfo<CL_DEVICE_MAX_COMPUTE_UNITS>(devices[d]);
      e.globalMemBytes = deviceInfo<CL_DEVICE_GLOBAL_MEM_SIZE>(devices[d]);
      e.maxAllocBytes = deviceInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>(devices[d]);
      e.localMemBytes = deviceInfo<CL_DEVICE_LOCAL_MEM_SIZE>(devices[d]);
      e.maxWorkGroupSize = deviceInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>(devices[d]);
      out.push_back(std::move(e));
    }
  }
  return out;
}

NoDeviceError::NoDeviceError()
    : RuntimeError(
          "no OpenCL device found; install an OpenCL driver (for the CPU: apt-get install "
          "pocl-opencl-icd)") {}

const DeviceEntry& selectDevice(const std::vector<DeviceEntry>& devices, const std::string& spec) {
  if (devices.empty()) throw NoDeviceError();
  const std::string s = lower(trimmed(spec));
  if (s.empty() || s == "default") {
    for (const auto& d : devices)
      if (d.type & CL_DEVICE_TYPE_GPU) return d;
    for (const auto& d : devices)
      if (d.type & CL_DEVICE_TYPE_CPU) return d;
    return devices.front();
  }
  auto refuse = [&](const std::string& why) -> const DeviceEntry& {
    throw InputError("--device " + spec + ": " + why + " (run 'pathreuse devices' for the list)");
  };
  int index = 0;
  if (parseUnsigned(s, &index)) {
    if (index < static_cast<int>(devices.size())) return devices[index];
    return refuse("no device with index " + s + "; there are " + std::to_string(devices.size()));
  }
  const size_t colon = s.find(':');
  int p = 0, d = 0;
  if (colon != std::string::npos && parseUnsigned(s.substr(0, colon), &p) &&
      parseUnsigned(s.substr(colon + 1), &d)) {
    for (const auto& e : devices)
      if (e.platformIndex == p && e.deviceIndex == d) return e;
    return refuse("no device " + std::to_string(d) + " on platform " + std::to_string(p));
  }
  if (s == "cpu" || s == "gpu") {
    const cl_device_type want = s == "cpu" ? CL_DEVICE_TYPE_CPU : CL_DEVICE_TYPE_GPU;
    for (const auto& e : devices)
      if (e.type & want) return e;
    return refuse("no " + s + " device");
  }
  for (const auto& e : devices)
    if (lower(e.name).find(s) != std::string::npos) return e;
  for (const auto& e : devices)
    if (lower(e.platformName).find(s) != std::string::npos ||
        lower(e.platformVendor).find(s) != std::string::npos)
      return e;
  return refuse("no device or platform whose name contains '" + spec + "'");
}

std::vector<const DeviceEntry*> selectDevices(const std::vector<DeviceEntry>& devices,
                                              const std::vector<std::string>& specs) {
  if (devices.empty()) throw NoDeviceError();
  if (specs.empty()) return {&selectDevice(devices, "")};
  std::vector<const DeviceEntry*> out;
  for (const auto& spec : specs) {
    if (lower(trimmed(spec)) == "all") {
      if (specs.size() > 1)
        throw InputError(
            "--device all: names every device; it cannot be combined with another "
            "--device");
      for (const auto& d : devices) out.push_back(&d);
      return out;
    }
    const DeviceEntry& d = selectDevice(devices, spec);
    for (const DeviceEntry* e : out)
      if (e == &d)
        throw InputError("--device " + spec + ": names device [" + std::to_string(d.index) + "] " +
                         d.name + ", which another --device already names");
    out.push_back(&d);
  }
  return out;
}

std::string describeDevice(const DeviceEntry& d) {
  std::ostringstream os;
  os << "[" << d.index << "] " << d.platformIndex << ":" << d.deviceIndex << "  " << d.name << "  ("
     << d.platformName << ")  " << deviceTypeName(d.type) << ", " << d.computeUnits
     << " compute units, " << formatBytes(d.globalMemBytes) << " global, max alloc "
     << formatBytes(d.maxAllocBytes) << ", " << d.openclCVersion;
  return os.str();
}

std::string devicesJson(const std::vector<DeviceEntry>& devices) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const auto& d : devices) {
    list.push_back({{"index", d.index},
                    {"platform_index", d.platformIndex},
                    {"device_index", d.deviceIndex},
                    {"platform", d.platformName},
                    {"platform_vendor", d.platformVendor},
                    {"name", d.name},
                    {"type", deviceTypeName(d.type)},
                    {"compute_units", d.computeUnits},
                    {"global_mem_bytes", d.globalMemBytes},
                    {"max_alloc_bytes", d.maxAllocBytes},
                    {"opencl_c_version", d.openclCVersion},
                    {"driver_version", d.driverVersion}});
  }
  nlohmann::ordered_json root;
  root["devices"] = std::move(list);
  return root.dump();
}

}  // namespace pr
