#include "util/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "util/error.h"
#include "util/files.h"

namespace pr {

namespace {

namespace fs = std::filesystem;

// The reason a file of this mode and size is refused, or "".
std::string whyNot(const struct stat& st, uint64_t maxBytes) {
  if (S_ISDIR(st.st_mode)) return "is a directory";
  if (S_ISFIFO(st.st_mode)) return "is not a regular file (a FIFO)";
  if (S_ISCHR(st.st_mode)) return "is not a regular file (a character device)";
  if (S_ISBLK(st.st_mode)) return "is not a regular file (a block device)";
  if (S_ISSOCK(st.st_mode)) return "is not a regular file (a socket)";
  if (!S_ISREG(st.st_mode)) return "is not a regular file";
  const uint64_t size = uint64_t(st.st_size);
  if (size > maxBytes)
    return "is " + formatBytes(size) + ", over the " + formatBytes(maxBytes) +
           " limit on files pathreuse reads";
  return "";
}

// Closes the descriptor on every path out.
struct Fd {
  explicit Fd(int f) : fd(f) {}
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int fd;
};

}  // namespace

std::vector<uint8_t> readInputFile(const std::string& path, uint64_t maxBytes) {
  auto fail = [&](const std::string& why) -> void { throw InputError(path + ": " + why); };
  // O_NONBLOCK: opening a FIFO with no writer would otherwise wait for one for ever. The checks
  // are on the open descriptor, so the file cannot be swapped between check and read.
  Fd f(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
  if (f.fd < 0)
    fail(errno == ENOENT ? "no such file" : std::string("cannot open: ") + std::strerror(errno));
  struct stat st = {};
  if (::fstat(f.fd, &st) != 0) fail(std::string("cannot read: ") + std::strerror(errno));
  const std::string why = whyNot(st, maxBytes);
  if (!why.empty()) fail(why);
  const size_t size = size_t(st.st_size);
  std::vector<uint8_t> bytes(size);
  size_t got = 0;
  while (got < size) {
    const ssize_t n = ::read(f.fd, bytes.data() + got, std::min<size_t>(size - got, 1 << 24));
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(std::string("cannot read: ") + std::strerror(errno));
    }
    if (n == 0) fail("is shorter than its size (" + formatBytes(size) + "): changed while read");
    got += size_t(n);
  }
  return bytes;
}

std::string readInputFileText(const std::string& path, uint64_t maxBytes) {
  const std::vector<uint8_t> bytes = readInputFile(path, maxBytes);
  return std::string(bytes.begin(), bytes.end());
}

std::string whyOutsideRoot(const std::string& root, const std::string& path) {
  std::error_code ec;
  const fs::path base = fs::weakly_canonical(fs::absolute(root.empty() ? "." : root, ec), ec);
  if (ec) return "cannot resolve the scene's folder " + root + ": " + ec.message();
  const fs::path target = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) return "cannot resolve: " + ec.message();
  // Component by component: /scene-other is not inside /scene.
  auto b = base.begin(), t = target.begin();
  for (; b != base.end(); ++b, ++t) {
    if (b->empty()) continue;  // a trailing separator
    if (t == target.end() || *b != *t)
      return "resolves to " + target.string() + ", outside the scene's folder " + base.string() +
             " (--allow-outside-uris permits it)";
  }
  return "";
}

}  // namespace pr
