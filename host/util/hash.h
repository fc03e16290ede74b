// A small non-cryptographic 128-bit hash (two FNV-1a lanes) for cache keys and checksums.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace pr {

class Hash128 {
 public:
  Hash128& add(const void* data, size_t size);
  Hash128& add(const std::string& s);  // length-prefixed, so ("ab","c") != ("a","bc")
  std::string hex() const;
  uint64_t low() const { return a_; }

 private:
  uint64_t a_ = 0xcbf29ce484222325ull;
  uint64_t b_ = 0x84222325cbf29ce4ull;
};

}  // namespace pr
