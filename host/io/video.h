// A sequence's frames as one video file (--video), encoded by Debian's ffmpeg from the frames'
// PNGs: the same sRGB images, so the video shows what the PNGs show.
#pragma once

#include <string>
#include <vector>

namespace pr {

// The ffmpeg executable on PATH, or "" where there is none.
std::string findFfmpeg();

// Whether `path` ends in a container --video writes: .mp4, .mov or .mkv.
bool videoContainerKnown(const std::string& path);

// Encodes the PNG files `frames`, in order, at `fps` frames a second into `out` (H.264, 4:2:0,
// an odd width or height padded by one black line), through a temporary file beside it renamed
// at the end, so that `out` is whole or absent. Throws RuntimeError naming `out`, with ffmpeg's
// last message, where ffmpeg fails.
void encodeVideo(const std::string& ffmpeg, const std::vector<std::string>& frames, double fps,
                 const std::string& out);

}  // namespace pr
