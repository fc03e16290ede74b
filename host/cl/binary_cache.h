// The kernel cache's file format: a header (a magic that versions the format, the key the file
// was made for, the binary's size, a checksum of key and binary), then the driver's binary. A
// file can be copied or renamed: a reader gets the binary only where the key it asks with is the
// file's and the checksum holds, so another program's binary under this name is never loaded.
#pragma once

#include <cstddef>
#include <string>

namespace pr {

// A key: Hash128 hex of source, options, platform, device, driver and device version.
constexpr size_t kCacheKeyChars = 32;

// The format's version, hashed into every key (another version's files have other names).
std::string cacheFormatTag();

// The file's bytes for `binary` under `key` (kCacheKeyChars characters).
std::string packCacheFile(const std::string& key, const std::string& binary);

// The binary a cache file holds for `key`; empty where the file is of another format or key, is
// not as long as its header says, holds no binary, or its checksum fails.
std::string unpackCacheFile(const std::string& data, const std::string& key);

}  // namespace pr
