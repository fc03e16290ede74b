#include "cl/binary_cache.h"

#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <vector>

#include "util/check.h"
#include "util/files.h"

namespace pr {

namespace {

constexpr char kCacheMagic[8] = {'P', 'R', 'K', 'B', 'I', 'N', '0', '3'};
constexpr size_t kMacBytes = 32;

struct CacheHeader {
  char magic[8];
  char key[kCacheKeyChars];
  uint64_t size;
  unsigned char mac[kMacBytes];
};

// Why the secret `st` (of `what`) could be known to someone else; empty where it could not.
std::string openToOthers(const struct stat& st, const std::string& what) {
  if (st.st_uid != geteuid()) return what + " belongs to another user";
  if ((st.st_mode & (S_IRWXG | S_IRWXO)) != 0) return what + " is open to other users";
  return {};
}

std::string readSecret(const std::string& file, std::string* why) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return {};
  struct stat st {};
  std::string secret(kCacheSecretBytes, '\0');
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || uint64_t(st.st_size) != kCacheSecretBytes) {
    *why = file + " is not a " + std::to_string(kCacheSecretBytes) + "-byte file";
  } else if (std::string open = openToOthers(st, file); !open.empty()) {
    *why = open;
  } else if (::read(fd, &secret[0], secret.size()) != ssize_t(secret.size())) {
    *why = file + " could not be read";
  }
  ::close(fd);
  return why->empty() ? secret : std::string();
}

// A new secret in `file`, written whole under a temporary name and linked into place, so that
// two first runs agree on one (the second link fails and that run reads the first's).
bool makeSecret(const std::string& file) {
  unsigned char bytes[kCacheSecretBytes];
  if (RAND_bytes(bytes, sizeof bytes) != 1) return false;
  const std::string tmp = temporaryNameFor(file);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) return false;
  const bool written = ::write(fd, bytes, sizeof bytes) == ssize_t(sizeof bytes);
  OPENSSL_cleanse(bytes, sizeof bytes);
  const bool closed = ::close(fd) == 0;
  const bool linked =
      written && closed && (::link(tmp.c_str(), file.c_str()) == 0 || errno == EEXIST);
  ::unlink(tmp.c_str());
  return linked;
}

}  // namespace

std::string cacheFormatTag() {
  return std::string(kCacheMagic, sizeof kCacheMagic);
}

std::string driverEnvironmentTag() {
  // Variables of these prefixes that place, log or limit work, and leave the code alone.
  static const char* const kRuntimeOnly[] = {
      "POCL_AFFINITY",     "POCL_CACHE_DIR",         "POCL_DEBUG",        "POCL_DEVICES",
      "POCL_KERNEL_CACHE", "POCL_MAX_PTHREAD_COUNT", "POCL_MEMORY_LIMIT", "POCL_TRACING"};
  std::vector<std::string> lines;
  for (char** e = environ; e && *e; ++e) {
    const std::string entry = *e;
    if (entry.rfind("POCL_", 0) != 0 && entry.rfind("CL_CONFIG_", 0) != 0) continue;
    const std::string name = entry.substr(0, entry.find('='));
    const bool runtimeOnly = std::any_of(std::begin(kRuntimeOnly), std::end(kRuntimeOnly),
                                         [&](const char* r) { return name.rfind(r, 0) == 0; });
    if (!runtimeOnly) lines.push_back(entry);
  }
  std::sort(lines.begin(), lines.end());
  std::string tag;
  for (const std::string& l : lines) tag += l + "\n";
  return tag;
}

std::string cacheFileMac(const std::string& secret, const std::string& key,
                         const std::string& binary) {
  PR_CHECK(secret.size() == kCacheSecretBytes);
  unsigned char mac[EVP_MAX_MD_SIZE];
  unsigned int macBytes = 0;
  // The key's length is fixed, so key || binary is unambiguous.
  std::string message = key + binary;
  const unsigned char* done =
      HMAC(EVP_sha256(), secret.data(), int(secret.size()),
           reinterpret_cast<const unsigned char*>(message.data()), message.size(), mac, &macBytes);
  PR_CHECK(done != nullptr && macBytes == kMacBytes);
  return std::string(reinterpret_cast<const char*>(mac), kMacBytes);
}

std::string packCacheFile(const std::string& key, const std::string& binary,
                          const std::string& secret) {
  CacheHeader h;
  PR_CHECK(key.size() == sizeof h.key);
  std::memcpy(h.magic, kCacheMagic, sizeof kCacheMagic);
  std::memcpy(h.key, key.data(), sizeof h.key);
  h.size = binary.size();
  std::memcpy(h.mac, cacheFileMac(secret, key, binary).data(), kMacBytes);
  return std::string(reinterpret_cast<const char*>(&h), sizeof h) + binary;
}

std::string unpackCacheFile(const std::string& data, const std::string& key,
                            const std::string& secret) {
  CacheHeader h;
  if (data.size() < sizeof h || key.size() != sizeof h.key || secret.size() != kCacheSecretBytes)
    return {};
  std::memcpy(&h, data.data(), sizeof h);
  if (std::memcmp(h.magic, kCacheMagic, sizeof kCacheMagic) != 0 ||
      std::memcmp(h.key, key.data(), sizeof h.key) != 0 || h.size != data.size() - sizeof h ||
      h.size == 0)
    return {};
  std::string binary = data.substr(sizeof h);
  if (CRYPTO_memcmp(cacheFileMac(secret, key, binary).data(), h.mac, kMacBytes) != 0) return {};
  return binary;
}

std::string cacheSecret(const std::string& dir, std::string* why) {
  why->clear();
  ::mkdir(dir.c_str(), 0700);
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    *why = dir + " is not a folder";
    return {};
  }
  const std::string file = dir + "/secret";
  std::string secret = readSecret(file, why);
  if (secret.empty() && why->empty()) {
    if (!makeSecret(file)) {
      *why = file + " could not be made";
      return {};
    }
    secret = readSecret(file, why);
  }
  return secret;
}

}  // namespace pr
