#include "render/denoise.h"

#include <dlfcn.h>
#include <elf.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
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

// Why the shared object at `path` cannot be loaded safely ("" where it can): it must be a regular
// file (a FIFO is refused, never waited on) and an ELF shared object of this machine whose
// headers and loaded segments lie within the file. dlopen maps a file cut short and dies of
// SIGBUS on its first missing page, so a cut library must be refused before it.
std::string whyNotLoadable(const std::string& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return std::string("cannot be opened: ") + std::strerror(errno);
  struct stat st {};
  std::string why;
  Elf64_Ehdr eh{};
  const auto within = [&](uint64_t offset, uint64_t bytes) {
    return offset <= uint64_t(st.st_size) && bytes <= uint64_t(st.st_size) - offset;
  };
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    why = "is not a regular file";
  } else if (pread(fd, &eh, sizeof eh, 0) != ssize_t(sizeof eh) ||
             std::memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0 || eh.e_ident[EI_CLASS] != ELFCLASS64 ||
             eh.e_type != ET_DYN || eh.e_phentsize != sizeof(Elf64_Phdr)) {
    why = "is not a 64-bit ELF shared object";
#if defined(__x86_64__)
  } else if (eh.e_machine != EM_X86_64) {
    why = "is built for another processor";
#elif defined(__aarch64__)
  } else if (eh.e_machine != EM_AARCH64) {
    why = "is built for another processor";
#endif
  } else if (!within(eh.e_phoff, uint64_t(eh.e_phnum) * sizeof(Elf64_Phdr))) {
    why = "is cut short (its program headers lie past its end)";
  } else {
    for (int i = 0; i < eh.e_phnum && why.empty(); ++i) {
      Elf64_Phdr ph{};
      const off_t at = off_t(eh.e_phoff + uint64_t(i) * sizeof ph);
      if (pread(fd, &ph, sizeof ph, at) != ssize_t(sizeof ph))
        why = "cannot be read";
      else if (ph.p_type != PT_NULL && !within(ph.p_offset, ph.p_filesz))
        why = "is cut short (a segment lies past its end)";
    }
  }
  close(fd);
  return why;
}

// The library and every shared object in its folder (the core and device modules OIDN loads
// beside it, and TBB): checked before any is loaded. Throws InputError naming the file.
void checkLibraryFolder(const std::string& library) {
  std::vector<std::string> files = {library};
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::path(library).parent_path();
  for (const auto& e : std::filesystem::directory_iterator(dir.empty() ? "." : dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("lib", 0) == 0 && name.find(".so") != std::string::npos)
      files.push_back(e.path().string());
  }
  for (const std::string& f : files)
    if (const std::string why = whyNotLoadable(f); !why.empty())
      throw InputError("--denoise: " + f + " " + why +
                       " (reinstall it with: bash tools/setup/oidn.sh)");
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
    // A path is checked first; a bare name is the system's, found by the dynamic loader.
    const bool isPath = path.find('/') != std::string::npos;
    std::error_code ec;
    if (isPath && !std::filesystem::exists(std::filesystem::symlink_status(path, ec))) {
      looked += (looked.empty() ? "" : ", ") + path;
      continue;
    }
    if (isPath) checkLibraryFolder(path);
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
