#include "util/hash.h"

#include <cstdio>

namespace pr {

Hash128& Hash128::add(const void* data, size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    a_ = (a_ ^ p[i]) * 0x100000001b3ull;
    b_ = (b_ ^ p[i]) * 0x100000001b3ull;
    b_ ^= b_ >> 29;  // decorrelates the second lane from the first
  }
  return *this;
}

Hash128& Hash128::add(const std::string& s) {
  const uint64_t n = s.size();
  add(&n, sizeof n);
  return add(s.data(), s.size());
}

std::string Hash128::hex() const {
  char buf[33];
  std::snprintf(buf, sizeof buf, "%016llx%016llx", static_cast<unsigned long long>(a_),
                static_cast<unsigned long long>(b_));
  return buf;
}

}  // namespace pr
