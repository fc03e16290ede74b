#include "scene/image_decode.h"

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstring>
#include <string>

#include <zlib.h>

// Static functions only, so another stb_image in the same program cannot clash with ours.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#endif
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace pr {

namespace {

uint32_t bigEndian32(const uint8_t* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}

// A PNG's chunks: none longer than the file holds (stb grows its buffer to the claimed length
// before reading), every critical chunk's CRC right (stb checks none; libpng refuses a bad one,
// which is how a flipped byte shows), and an IEND (a cut file has none).
bool pngComplete(const std::vector<uint8_t>& e, std::string* why) {
  std::vector<size_t> chunks;
  size_t pos = 8;
  bool end = false;
  while (!end && pos + 12 <= e.size()) {
    const uint64_t len = bigEndian32(&e[pos]);
    if (len > e.size() - pos - 12) {
      *why = "PNG chunk at byte " + std::to_string(pos) + " claims " + std::to_string(len) +
             " bytes, more than the file holds";
      return false;
    }
    chunks.push_back(pos);
    end = std::memcmp(&e[pos + 4], "IEND", 4) == 0;
    pos += 12 + size_t(len);
  }
  if (!end) {
    *why = "PNG is truncated (no IEND chunk)";
    return false;
  }
  for (size_t at : chunks) {
    const uInt len = uInt(bigEndian32(&e[at]));
    const bool critical = (e[at + 4] & 0x20) == 0;
    if (critical &&
        crc32(crc32(0L, Z_NULL, 0), &e[at + 4], len + 4) != bigEndian32(&e[at + 8 + len])) {
      *why = "PNG chunk at byte " + std::to_string(at) + " is corrupt (bad CRC)";
      return false;
    }
  }
  return true;
}

// A JPEG's entropy-coded data cannot hold FF D9 (an FF there is followed by 00 or a restart
// marker), so one after the first start-of-scan is the end of the image: a cut file lacks it.
bool jpegComplete(const std::vector<uint8_t>& e, std::string* why) {
  size_t sos = 2;
  while (sos + 1 < e.size() && !(e[sos] == 0xff && e[sos + 1] == 0xda)) ++sos;
  for (size_t i = sos + 2; i + 1 < e.size(); ++i)
    if (e[i] == 0xff && e[i + 1] == 0xd9) return true;
  *why = "JPEG is truncated (no end-of-image marker)";
  return false;
}

// A Radiance .hdr holds every scanline the header promises: stb reads past the end as zeros
// (a black band, silently). Walks the scanlines as stb reads them: run-length encoded ones
// (2, 2, width) with four channels of runs, else flat RGBE from there on.
bool hdrComplete(const std::vector<uint8_t>& e, std::string* why) {
  size_t pos = 0;
  bool blank = false;
  while (pos < e.size() && !blank) {  // header lines up to an empty one
    const size_t eol = std::find(e.begin() + long(pos), e.end(), uint8_t('\n')) - e.begin();
    blank = eol == pos;
    pos = eol + 1;
  }
  const size_t eol =
      std::find(e.begin() + long(std::min(pos, e.size())), e.end(), uint8_t('\n')) - e.begin();
  int h = 0, w = 0;
  const std::string res(e.begin() + long(std::min(pos, e.size())), e.begin() + long(eol));
  if (!blank || std::sscanf(res.c_str(), "-Y %d +X %d", &h, &w) != 2 || w <= 0 || h <= 0) {
    *why = "Radiance HDR header is incomplete or not -Y H +X W";
    return false;
  }
  pos = eol + 1;
  auto truncated = [&](int row) {
    *why = "Radiance HDR is truncated: " + std::to_string(row) + " of " + std::to_string(h) +
           " scanlines";
    return false;
  };
  for (int row = 0; row < h; ++row) {
    const bool rle = w >= 8 && w < 32768 && pos + 4 <= e.size() && e[pos] == 2 && e[pos + 1] == 2 &&
                     (e[pos + 2] & 0x80) == 0;
    if (!rle) {  // stb reads the rest flat
      if ((e.size() - std::min(pos, e.size())) / 4 < uint64_t(w) * uint64_t(h - row))
        return truncated(row);
      return true;
    }
    pos += 4;
    for (int c = 0; c < 4; ++c)
      for (int i = 0; i < w;) {
        if (pos >= e.size()) return truncated(row);
        int count = e[pos++];
        if (count > 128) {
          count -= 128;
          pos += 1;
        } else {
          pos += size_t(count);
        }
        if (count == 0 || pos > e.size()) return truncated(row);
        i += count;
      }
  }
  return true;
}

// Checks what stb_image would otherwise trust: the declared size (it allocates width x height
// x 4 bytes up front) and that the file is whole (PNG, JPEG, Radiance HDR): stb decodes a cut
// file's missing part as zeros. A tiny file must not cost gigabytes, nor a cut one give a frame.
bool plausibleImage(const std::vector<uint8_t>& e, std::string* why) {
  int w = 0, h = 0, comp = 0;
  if (stbi_info_from_memory(e.data(), int(e.size()), &w, &h, &comp)) {
    if (w <= 0 || h <= 0 || uint64_t(w) * uint64_t(h) > kMaxImagePixels) {
      *why = "image is " + std::to_string(w) + " x " + std::to_string(h) + " pixels, over the " +
             std::to_string(kMaxImagePixels) + " pathreuse loads";
      return false;
    }
  }
  static const uint8_t kPng[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  if (e.size() >= 8 && std::memcmp(e.data(), kPng, 8) == 0) return pngComplete(e, why);
  if (e.size() >= 3 && e[0] == 0xff && e[1] == 0xd8 && e[2] == 0xff) return jpegComplete(e, why);
  if (e.size() >= 2 && e[0] == '#' && e[1] == '?') return hdrComplete(e, why);
  return true;
}

}  // namespace

bool decodeImageRgba8(const std::vector<uint8_t>& encoded, DecodedImage* out, std::string* why) {
  if (encoded.empty() || encoded.size() > size_t(INT_MAX)) {
    *why = encoded.empty() ? "no image data" : "image data too large";
    return false;
  }
  if (!plausibleImage(encoded, why)) return false;
  int w = 0, h = 0, channels = 0;
  stbi_uc* pixels =
      stbi_load_from_memory(encoded.data(), int(encoded.size()), &w, &h, &channels, 4);
  if (!pixels) {
    const char* reason = stbi_failure_reason();
    *why = reason ? reason : "unknown format";
    return false;
  }
  out->width = w;
  out->height = h;
  out->rgba8.assign(pixels, pixels + size_t(w) * size_t(h) * 4);
  stbi_image_free(pixels);
  return true;
}

bool decodeImageRgbFloat(const std::vector<uint8_t>& encoded, int* width, int* height,
                         std::vector<float>* rgb, std::string* why) {
  if (encoded.empty() || encoded.size() > size_t(INT_MAX)) {
    *why = encoded.empty() ? "no image data" : "image data too large";
    return false;
  }
  if (!plausibleImage(encoded, why)) return false;
  int w = 0, h = 0, channels = 0;
  float* pixels = stbi_loadf_from_memory(encoded.data(), int(encoded.size()), &w, &h, &channels, 3);
  if (!pixels) {
    const char* reason = stbi_failure_reason();
    *why = reason ? reason : "unknown format";
    return false;
  }
  *width = w;
  *height = h;
  rgb->assign(pixels, pixels + size_t(w) * size_t(h) * 3);
  stbi_image_free(pixels);
  return true;
}

}  // namespace pr
