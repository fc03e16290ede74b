// Enumerating OpenCL platforms and devices and choosing one from a --device SPEC.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cl/cl.h"

namespace pr {

struct DeviceEntry {
  int index = 0;          // position in the flat list of all devices
  int platformIndex = 0;  // P in "P:D"
  int deviceIndex = 0;    // D in "P:D"
  cl::Platform platform;
  cl::Device device;
  std::string platformName;
  std::string platformVendor;  // "The pocl project", "Intel(R) Corporation", ...
  std::string name;
  std::string vendor;
  std::string driverVersion;
  std::string deviceVersion;
  std::string openclCVersion;
  cl_device_type type = 0;
  uint32_t computeUnits = 0;
  uint64_t globalMemBytes = 0;
  uint64_t maxAllocBytes = 0;
  uint64_t localMemBytes = 0;
  size_t maxWorkGroupSize = 0;
};

// "CPU", "GPU", "ACCELERATOR" or "OTHER".
std::string deviceTypeName(cl_device_type type);

// Every device of every platform, in platform order. Empty when there is no platform.
std::vector<DeviceEntry> enumerateDevices();

// Raised when no OpenCL device exists at all (exit code 1).
class NoDeviceError : public RuntimeError {
 public:
  NoDeviceError();
};

// Picks a device from SPEC: an index in the list, "P:D", "cpu", "gpu", or a case-insensitive
// substring of the device name, else of the platform's name or vendor (so "pocl", "intel(r)
// opencl" and "nvidia" name a platform whatever its devices are called). An empty SPEC picks the
// first GPU, else the first CPU, else the first device. Throws NoDeviceError when `devices` is
// empty and InputError when SPEC matches nothing.
const DeviceEntry& selectDevice(const std::vector<DeviceEntry>& devices, const std::string& spec);

// The devices of several SPECs, in order: each as selectDevice picks it (no SPEC: the default
// one), or "all" alone for every device. Throws InputError naming the SPEC that matches nothing,
// names a device another SPEC names, or combines "all" with others.
std::vector<const DeviceEntry*> selectDevices(const std::vector<DeviceEntry>& devices,
                                              const std::vector<std::string>& specs);

// One line describing a device, as `pathreuse devices` prints it.
std::string describeDevice(const DeviceEntry& d);

// {"devices": [...]} as `pathreuse devices --json` prints it.
std::string devicesJson(const std::vector<DeviceEntry>& devices);

}  // namespace pr
