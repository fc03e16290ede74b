// File helpers: whole-file reads and atomic writes (temporary name, then rename), so that a
// file is either complete or absent.
#pragma once

#include <cstdint>
#include <string>

namespace pr {

// A byte count for messages: "812 bytes", "3.4 MiB", "4.00 GiB".
std::string formatBytes(uint64_t bytes);

// Reads a whole regular file (util/input_file.h's opener); false when it cannot be read.
bool readFile(const std::string& path, std::string* out);

// Writes `data` to `path` through a temporary file in the same folder and a rename. Creates
// missing parent folders. Throws RuntimeError naming the file on failure (and leaves no
// temporary file behind).
void writeFileAtomic(const std::string& path, const std::string& data);

// Checks, before any work, that `path` could be written: creates its missing parent folders and
// a temporary file beside it, then removes that file. Throws RuntimeError naming `path`.
void checkWritable(const std::string& path);

// A unique temporary name beside `path` (same folder, so rename is atomic).
std::string temporaryNameFor(const std::string& path);

// A hash of this program's executable file (hex; "unknown" where it cannot be read), so that a
// file derived by one build is not taken for another's. Read once per process.
const std::string& executableDigest();

}  // namespace pr
