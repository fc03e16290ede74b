#include "cl/binary_cache.h"

#include <cstdint>
#include <cstring>

#include "util/check.h"
#include "util/hash.h"

namespace pr {

namespace {

constexpr char kCacheMagic[8] = {'P', 'R', 'K', 'B', 'I', 'N', '0', '2'};

struct CacheHeader {
  char magic[8];
  char key[kCacheKeyChars];
  uint64_t size;
  uint64_t checksum;
};

uint64_t cacheChecksum(const std::string& key, const std::string& binary) {
  return Hash128().add(key).add(binary).low();
}

}  // namespace

std::string cacheFormatTag() {
  return std::string(kCacheMagic, sizeof kCacheMagic);
}

std::string packCacheFile(const std::string& key, const std::string& binary) {
  CacheHeader h;
  PR_CHECK(key.size() == sizeof h.key);
  std::memcpy(h.magic, kCacheMagic, sizeof kCacheMagic);
  std::memcpy(h.key, key.data(), sizeof h.key);
  h.size = binary.size();
  h.checksum = cacheChecksum(key, binary);
  return std::string(reinterpret_cast<const char*>(&h), sizeof h) + binary;
}

std::string unpackCacheFile(const std::string& data, const std::string& key) {
  CacheHeader h;
  if (data.size() < sizeof h || key.size() != sizeof h.key) return {};
  std::memcpy(&h, data.data(), sizeof h);
  if (std::memcmp(h.magic, kCacheMagic, sizeof kCacheMagic) != 0 ||
      std::memcmp(h.key, key.data(), sizeof h.key) != 0 || h.size != data.size() - sizeof h ||
      h.size == 0)
    return {};
  std::string binary = data.substr(sizeof h);
  if (cacheChecksum(key, binary) != h.checksum) return {};
  return binary;
}

}  // namespace pr
