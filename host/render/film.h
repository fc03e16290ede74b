// The film: per pixel, the sum of sample radiance and the number of samples, on the device.
// A device rendering part of the image (render/multi_device.h) owns a range of whole rows;
// its integrator launches its pixel kernels over that range alone.
#pragma once

#include <cstdint>
#include <vector>

#include "cl/context.h"
#include "io/image.h"
#include "cl/stage_timer.h"

namespace pr {

class Film {
 public:
  Film(Context& ctx, int width, int height);

  void clear();
  // Adds the radiance (float4 per pixel, indexed by pixel) of the range's pixels.
  void accumulate(const cl::Buffer& radiance, StageTimer* timer);
  // Adds the range's fixed-point splats (kernels/shared/splat.h, 6 words per pixel, indexed by
  // pixel) times `scale` to the sums, not to the counts, and clears them where `clear`.
  void addSplats(const cl::Buffer& splat, StageTimer* timer, float scale = 1.0f, bool clear = true);
  // The mean radiance per pixel (alpha 1), and how many samples were non-finite and dropped.
  Image read(uint64_t* badSamples = nullptr);
  // The same for the range's rows only, written into `image` (of the film's size).
  void readRows(Image* image, uint64_t* badSamples = nullptr);
  // The range's sums as they stand (rgb sum and sample count per pixel, 4 floats), for films
  // of several devices that are added before the mean (render/multi_device.h).
  std::vector<float> readSums(uint64_t* badSamples = nullptr);
  // The mean of n pixels' sums into n rgba pixels (alpha 1; 0 where no sample counted).
  static void mean(const float* sums, size_t n, float* rgba);

  // Rows [rowBegin, rowEnd) are rendered (default: all).
  void setRows(int rowBegin, int rowEnd);
  int rowBegin() const { return rowBegin_; }
  int rowEnd() const { return rowEnd_; }
  // The range as pixel indices [first, end).
  uint32_t first() const { return static_cast<uint32_t>(rowBegin_) * width_; }
  uint32_t end() const { return static_cast<uint32_t>(rowEnd_) * width_; }

  int width() const { return width_; }
  int height() const { return height_; }
  uint32_t pixels() const { return static_cast<uint32_t>(width_) * height_; }

 private:
  Context& ctx_;
  int width_, height_;
  int rowBegin_ = 0, rowEnd_ = 0;
  cl::Buffer film_, bad_;
  cl::Kernel accumulate_, splatFilm_;
};

}  // namespace pr
