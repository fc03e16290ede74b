// Frame images: linear RGBA float in memory, written as OpenEXR (half or float) and as sRGB PNG.
// Every file is written under a temporary name and renamed, so it is either complete or absent.
#pragma once

#include <string>
#include <vector>

namespace pr {

// An extra channel of an image (--aov), named as OpenEXR names channels ("albedo.R", "Z").
struct ImageChannel {
  std::string name;
  std::vector<float> values;  // one per pixel, row-major
  bool fullFloat = false;     // 32-bit in every EXR (depth, ids), else as the image's pixels
};

struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> rgba;             // row-major, top row first, 4 floats per pixel
  std::vector<ImageChannel> channels;  // written after R, G, B, A

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(static_cast<size_t>(w) * h * 4, 0.0f) {}
  float* pixel(int x, int y) { return &rgba[(static_cast<size_t>(y) * width + x) * 4]; }
  const float* pixel(int x, int y) const { return &rgba[(static_cast<size_t>(y) * width + x) * 4]; }
};

enum class ExrPixels { Half, Float };

// Throws RuntimeError naming the file when it cannot be written.
void writeExr(const std::string& path, const Image& image, ExrPixels pixels = ExrPixels::Half);

// sRGB 8-bit PNG of the linear image scaled by 2^exposure and clamped.
void writePng(const std::string& path, const Image& image, float exposure = 0.0f);

// Reads an OpenEXR file's RGBA channels (missing alpha = 1). Throws InputError naming the file
// when it is missing, truncated or not OpenEXR.
Image readExr(const std::string& path);

// One channel of an OpenEXR file, as floats. Throws InputError naming the file where it is
// missing or unreadable.
std::vector<float> readExrChannel(const std::string& path, const std::string& name);

// True when `path` is a complete, readable OpenEXR file.
bool isCompleteExr(const std::string& path);

}  // namespace pr
