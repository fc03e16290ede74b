#include "render/denoise.h"

#include <dlfcn.h>

#include <cstdlib>
#include <vector>

#include "util/error.h"

namespace pr {

namespace {

// OIDN 2's C API, the part used here (its header is not packaged: the types are OIDN's).
using Device = void*;
using Buffer = void*;
using Filter = void*;
constexpr int kDeviceDefault = 0;
constexpr int kFormatFloat3 = 3;
constexpr int kErrorNone = 0;

std::string cacheLibrary() {
  std::string root;
  if (const char* h = std::getenv("PATHREUSE_OPENCL_HOME"); h && *h) {
    root = h;
  } else if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) {
    root = std::string(x) + "/pathreuse";
  } else if (const char* home = std::getenv("HOME"); home && *home) {
    root = std::string(home) + "/.cache/pathreuse";
  } else {
    return "";
  }
  return root + "/oidn/libOpenImageDenoise.so.2";
}

}  // namespace

struct Denoiser::Api {
  void* lib = nullptr;
  Device device = nullptr;
  Device (*newDevice)(int);
  void (*commitDevice)(Device);
  void (*releaseDevice)(Device);
  int (*getDeviceInt)(Device, const char*);
  int (*getDeviceError)(Device, const char**);
  Buffer (*newBuffer)(Device, size_t);
  void (*writeBuffer)(Buffer, size_t, size_t, const void*);
  void (*readBuffer)(Buffer, size_t, size_t, void*);
  void (*releaseBuffer)(Buffer);
  Filter (*newFilter)(Device, const char*);
  void (*setFilterImage)(Filter, const char*, Buffer, int, size_t, size_t, size_t, size_t, size_t);
  void (*setFilterBool)(Filter, const char*, bool);
  void (*commitFilter)(Filter);
  void (*executeFilter)(Filter);
  void (*releaseFilter)(Filter);

  template <class F>
  void load(F* f, const char* name, const std::string& path) {
    *f = reinterpret_cast<F>(dlsym(lib, name));
    if (!*f)
      throw InputError("--denoise: " + path + " has no " + name + " (not Open Image Denoise 2)");
  }
  // Filters and buffers are made once per image size (OIDN's set-up of a filter is the costly
  // part): buffers colour, albedo, normal, output; filters albedo, normal, colour.
  int width = 0, height = 0;
  size_t bytes = 0;
  Buffer buffers[4] = {};
  Filter filters[3] = {};
  void prepare(int w, int h);
  void release();

  void check(const char* what) {
    const char* msg = nullptr;
    if (getDeviceError(device, &msg) != kErrorNone)
      throw RuntimeError(std::string("--denoise: Open Image Denoise failed to ") + what + ": " +
                         (msg ? msg : "unknown error"));
  }
};

Denoiser::Denoiser() : api_(std::make_unique<Api>()) {
  std::vector<std::string> tried;
  if (const char* p = std::getenv("PATHREUSE_OIDN"); p && *p) {
    tried.push_back(p);
  } else {
    if (const std::string c = cacheLibrary(); !c.empty()) tried.push_back(c);
    tried.push_back("libOpenImageDenoise.so.2");
  }
  std::string looked;
  for (const std::string& path : tried) {
    api_->lib = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (api_->lib) {
      looked = path;
      break;
    }
    looked += (looked.empty() ? "" : ", ") + path;
  }
  if (!api_->lib)
    throw InputError("--denoise: Open Image Denoise 2 not found (looked for " + looked +
                     "); install it with: bash tools/setup/oidn.sh");
  Api& a = *api_;
  a.load(&a.newDevice, "oidnNewDevice", looked);
  a.load(&a.commitDevice, "oidnCommitDevice", looked);
  a.load(&a.releaseDevice, "oidnReleaseDevice", looked);
  a.load(&a.getDeviceInt, "oidnGetDeviceInt", looked);
  a.load(&a.getDeviceError, "oidnGetDeviceError", looked);
  a.load(&a.newBuffer, "oidnNewBuffer", looked);
  a.load(&a.writeBuffer, "oidnWriteBuffer", looked);
  a.load(&a.readBuffer, "oidnReadBuffer", looked);
  a.load(&a.releaseBuffer, "oidnReleaseBuffer", looked);
  a.load(&a.newFilter, "oidnNewFilter", looked);
  a.load(&a.setFilterImage, "oidnSetFilterImage", looked);
  a.load(&a.setFilterBool, "oidnSetFilterBool", looked);
  a.load(&a.commitFilter, "oidnCommitFilter", looked);
  a.load(&a.executeFilter, "oidnExecuteFilter", looked);
  a.load(&a.releaseFilter, "oidnReleaseFilter", looked);
}

Denoiser::~Denoiser() {
  api_->release();
  if (api_->device) api_->releaseDevice(api_->device);
  // The library stays loaded: OIDN's threads may outlive the device briefly.
}

std::string Denoiser::deviceType() const {
  if (!api_->device) return "";
  switch (api_->getDeviceInt(api_->device, "type")) {
    case 1:
      return "CPU";
    case 2:
      return "SYCL";
    case 3:
      return "CUDA";
    case 4:
      return "HIP";
    case 5:
      return "Metal";
    default:
      return "unknown";
  }
}

void Denoiser::Api::prepare(int w, int h) {
  if (!device) {
    device = newDevice(kDeviceDefault);
    if (!device) throw RuntimeError("--denoise: Open Image Denoise has no device here");
    commitDevice(device);
    check("start its device");
  }
  if (w == width && h == height) return;
  release();
  width = w;
  height = h;
  bytes = size_t(w) * size_t(h) * 3 * sizeof(float);
  for (Buffer& b : buffers) b = newBuffer(device, bytes);
  check("allocate its buffers");
  auto image = [&](Filter f, const char* name, Buffer b) {
    setFilterImage(f, name, b, kFormatFloat3, size_t(w), size_t(h), 0, 0, 0);
  };
  // The auxiliary images alone first, each in place; then the colour with them.
  for (int k = 0; k < 2; ++k) {
    filters[k] = newFilter(device, "RT");
    image(filters[k], k == 0 ? "albedo" : "normal", buffers[1 + k]);
    image(filters[k], "output", buffers[1 + k]);
  }
  filters[2] = newFilter(device, "RT");
  image(filters[2], "color", buffers[0]);
  image(filters[2], "albedo", buffers[1]);
  image(filters[2], "normal", buffers[2]);
  image(filters[2], "output", buffers[3]);
  setFilterBool(filters[2], "hdr", true);
  setFilterBool(filters[2], "cleanAux", true);
  for (Filter f : filters) commitFilter(f);
  check("set up its filters");
}

void Denoiser::Api::release() {
  for (Filter& f : filters)
    if (f) releaseFilter(f), f = nullptr;
  for (Buffer& b : buffers)
    if (b) releaseBuffer(b), b = nullptr;
  width = height = 0;
}

void Denoiser::denoise(int w, int h, float* color, const float* albedo, const float* normal) {
  Api& a = *api_;
  a.prepare(w, h);
  a.writeBuffer(a.buffers[0], 0, a.bytes, color);
  a.writeBuffer(a.buffers[1], 0, a.bytes, albedo);
  a.writeBuffer(a.buffers[2], 0, a.bytes, normal);
  for (Filter f : a.filters) a.executeFilter(f);
  a.check("denoise the frame");
  a.readBuffer(a.buffers[3], 0, a.bytes, color);
  a.check("read its results");
}

}  // namespace pr
