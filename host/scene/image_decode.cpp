#include "scene/image_decode.h"

#include <climits>
#include <cstring>
#include <string>

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

// Checks what stb_image would otherwise trust: the declared size (it allocates width x height
// x 4 bytes up front) and, in a PNG, that no chunk claims more bytes than the file holds (it
// grows its buffer to the claimed length before reading). A tiny file must not cost gigabytes.
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
  if (e.size() >= 8 && std::memcmp(e.data(), kPng, 8) == 0) {
    size_t pos = 8;
    while (pos + 12 <= e.size()) {
      const uint64_t len = (uint64_t(e[pos]) << 24) | (uint64_t(e[pos + 1]) << 16) |
                           (uint64_t(e[pos + 2]) << 8) | uint64_t(e[pos + 3]);
      if (len > e.size() - pos - 12) {
        *why = "PNG chunk at byte " + std::to_string(pos) + " claims " + std::to_string(len) +
               " bytes, more than the file holds";
        return false;
      }
      if (std::memcmp(&e[pos + 4], "IEND", 4) == 0) break;
      pos += 12 + size_t(len);
    }
  }
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
