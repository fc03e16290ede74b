// The kernel cache's file format: a header (a magic that versions the format, the key the file
// was made for, the binary's size, an HMAC-SHA256 of key and binary under this user's cache
// secret), then the driver's binary. A file can be copied or renamed: a reader gets the binary
// only where the key it asks with is the file's and the MAC holds, so another program's binary
// under this name, or one this user's pathreuse did not write, never reaches the driver (which
// may crash on a damaged binary rather than refuse it).
#pragma once

#include <cstddef>
#include <string>

namespace pr {

// A key: Hash128 hex of source, options, platform, device, driver and device version, and the
// driver's code-generation environment (driverEnvironmentTag).
constexpr size_t kCacheKeyChars = 32;

// The cache secret's size in bytes (the HMAC key, kept beside the cache files).
constexpr size_t kCacheSecretBytes = 32;

// The format's version, hashed into every key (another version's files have other names).
std::string cacheFormatTag();

// The environment variables that steer a driver's compiler, as NAME=VALUE lines sorted by name:
// PoCL's (POCL_*) and Intel's CPU runtime's (CL_CONFIG_*), less those that only place or log
// work (POCL_CACHE_DIR, POCL_DEBUG*, POCL_MAX_PTHREAD_COUNT, ...). POCL_WORK_GROUP_METHOD
// changes the code a program binary holds, so a binary built under another value is not this
// run's program.
std::string driverEnvironmentTag();

// The MAC a file of `key` and `binary` carries under `secret` (32 bytes).
std::string cacheFileMac(const std::string& secret, const std::string& key,
                         const std::string& binary);

// The file's bytes for `binary` under `key` (kCacheKeyChars characters) and `secret`.
std::string packCacheFile(const std::string& key, const std::string& binary,
                          const std::string& secret);

// The binary a cache file holds for `key`; empty where the file is of another format or key, is
// not as long as its header says, holds no binary, or its MAC under `secret` fails.
std::string unpackCacheFile(const std::string& data, const std::string& key,
                            const std::string& secret);

// The cache secret of the folder `dir` (kCacheSecretBytes random bytes in DIR/secret, made at
// first use, mode 0600). Files in a folder others can write carry no MAC under it, since they
// cannot read it. Empty, with `*why` set, where the secret could be known to another user (not
// owned by this one, or open to group or others) or cannot be made: the cache is not used.
std::string cacheSecret(const std::string& dir, std::string* why);

}  // namespace pr
