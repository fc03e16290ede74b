#include "scene/image_decode.h"

#include <climits>
#include <cstring>

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

bool decodeImageRgba8(const std::vector<uint8_t>& encoded, DecodedImage* out, std::string* why) {
  if (encoded.empty() || encoded.size() > size_t(INT_MAX)) {
    *why = encoded.empty() ? "no image data" : "image data too large";
    return false;
  }
  int w = 0, h = 0, channels = 0;
  stbi_uc* pixels = stbi_load_from_memory(encoded.data(), int(encoded.size()), &w, &h, &channels, 4);
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

}  // namespace pr
