#include "util/files.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "util/error.h"
#include "util/hash.h"
#include "util/input_file.h"
#include "util/interrupt.h"

namespace pr {

std::string formatBytes(uint64_t bytes) {
  char buf[48];
  if (bytes >= (uint64_t(1) << 30))
    std::snprintf(buf, sizeof buf, "%.2f GiB", double(bytes) / double(uint64_t(1) << 30));
  else if (bytes >= (uint64_t(1) << 20))
    std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / double(uint64_t(1) << 20));
  else if (bytes >= 1024)
    std::snprintf(buf, sizeof buf, "%.1f KiB", double(bytes) / 1024.0);
  else
    std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(bytes));
  return buf;
}

bool readFile(const std::string& path, std::string* out) {
  try {
    *out = readInputFileText(path, kMaxBufferFileBytes);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

std::string temporaryNameFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  namespace fs = std::filesystem;
  const fs::path p(path);
  const std::string tail = ".tmp" + std::to_string(getpid()) + "_" + std::to_string(counter++);
  std::string name = "." + p.filename().string() + tail;
  // A name the file system takes whenever it takes the final one (255 bytes on Linux): a long
  // name is shortened, keeping its start and a hash of the whole.
  constexpr size_t kNameMax = 255;
  if (name.size() > kNameMax) {
    const std::string hash = Hash128().add(p.filename().string()).hex().substr(0, 16);
    name = "." + p.filename().string().substr(0, kNameMax - 2 - hash.size() - tail.size()) + "-" +
           hash + tail;
  }
  return (p.parent_path() / name).string();
}

namespace {

void createParent(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) {
    fs::create_directories(parent, ec);
    if (ec)
      throw RuntimeError(path + ": cannot create folder " + parent.string() + ": " + ec.message());
  }
}

}  // namespace

void checkWritable(const std::string& path) {
  createParent(path);
  const DeferInterrupts defer;
  const std::string tmp = temporaryNameFor(path);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw RuntimeError(path + ": cannot write: " + std::strerror(errno));
  std::fclose(f);
  std::remove(tmp.c_str());
}

void writeFileAtomic(const std::string& path, const std::string& data) {
  createParent(path);
  const DeferInterrupts defer;
  const std::string tmp = temporaryNameFor(path);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw RuntimeError(path + ": cannot write: " + std::strerror(errno));
  errno = 0;
  const size_t written = std::fwrite(data.data(), 1, data.size(), f);
  const int flushErr = std::fflush(f);
  const int err = errno;
  const int closeErr = std::fclose(f);
  if (written != data.size() || flushErr != 0 || closeErr != 0) {
    std::remove(tmp.c_str());
    throw RuntimeError(path + ": cannot write: " + std::strerror(err ? err : EIO));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int renameErr = errno;
    std::remove(tmp.c_str());
    throw RuntimeError(path + ": cannot write: " + std::strerror(renameErr));
  }
}

const std::string& executableDigest() {
  static const std::string digest = [] {
    std::string bytes;
    return readFile("/proc/self/exe", &bytes) ? Hash128().add(bytes).hex() : std::string("unknown");
  }();
  return digest;
}

}  // namespace pr
