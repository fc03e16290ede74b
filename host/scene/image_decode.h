// Decoding PNG/JPEG/BMP/... bytes to RGBA8 (stb_image, compiled privately here).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pr {

struct DecodedImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba8;  // width * height * 4, rows top to bottom
};

// The largest image loaded: 8192 x 8192 (256 MiB as RGBA8).
constexpr uint64_t kMaxImagePixels = uint64_t(8192) * 8192;

// False with `why` set when the bytes are not an image stb can read, declare more than
// kMaxImagePixels, or (PNG) hold a chunk longer than the data.
bool decodeImageRgba8(const std::vector<uint8_t>& encoded, DecodedImage* out, std::string* why);

// The same checks; linear RGB floats (3 per pixel), as Radiance .hdr files hold them.
bool decodeImageRgbFloat(const std::vector<uint8_t>& encoded, int* width, int* height,
                         std::vector<float>* rgb, std::string* why);

}  // namespace pr
