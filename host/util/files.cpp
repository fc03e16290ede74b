#include "util/files.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "util/error.h"

namespace pr {

bool readFile(const std::string& path, std::string* out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream os;
  os << in.rdbuf();
  if (in.bad()) return false;
  *out = os.str();
  return true;
}

std::string temporaryNameFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  namespace fs = std::filesystem;
  const fs::path p(path);
  const std::string name = "." + p.filename().string() + ".tmp" + std::to_string(getpid()) + "_" +
                           std::to_string(counter++);
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
  const std::string tmp = temporaryNameFor(path);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw RuntimeError(path + ": cannot write: " + std::strerror(errno));
  std::fclose(f);
  std::remove(tmp.c_str());
}

void writeFileAtomic(const std::string& path, const std::string& data) {
  createParent(path);
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

}  // namespace pr
