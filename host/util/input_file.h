// The one way the renderer reads a file it is given (scenes, their buffers and images,
// environment maps, EXRs it compares or resumes, portability references): regular files only,
// opened without blocking (a FIFO or a device is refused, never waited on), the size known and
// checked against a limit before a byte is read, and, for files a scene names, the path confined
// to the scene's folder. Every refusal is an InputError "PATH: reason".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pr {

// Limits on what is read (README.md "Limits" states them).
constexpr uint64_t kMaxSceneFileBytes = (uint64_t(1) << 32) - 1;   // .gltf/.glb: GLB's own limit
constexpr uint64_t kMaxBufferFileBytes = (uint64_t(1) << 32) - 1;  // a buffer's byteLength fits
// Maps and EXRs: a 16384 x 16384 float RGBA frame, the largest pathreuse writes, is 4 GiB raw.
constexpr uint64_t kMaxImageFileBytes = uint64_t(8) << 30;

// Reads the whole regular file at `path`, of at most `maxBytes`. Throws InputError
// "PATH: reason" (no such file, is a directory, is a FIFO, is N bytes over the limit, a read
// error, shorter than its size said).
std::vector<uint8_t> readInputFile(const std::string& path, uint64_t maxBytes);
std::string readInputFileText(const std::string& path, uint64_t maxBytes);

// Where a file named by a scene may be: `path` (already joined to the scene's folder) resolved
// through ".." and symbolic links must lie in `root` (the scene's folder) or below. Returns ""
// when it does, else the reason, naming where it resolves.
std::string whyOutsideRoot(const std::string& root, const std::string& path);

}  // namespace pr
