// The film: per pixel, the sum of sample radiance and the number of samples, on the device.
#pragma once

#include <cstdint>

#include "cl/context.h"
#include "io/image.h"
#include "cl/stage_timer.h"

namespace pr {

class Film {
 public:
  Film(Context& ctx, int width, int height);

  void clear();
  // Adds `count` samples' radiance (float4 each; sample i goes to pixel i % pixels).
  void accumulate(const cl::Buffer& radiance, uint32_t count, StageTimer* timer);
  // The mean radiance per pixel (alpha 1), and how many samples were non-finite and dropped.
  Image read(uint64_t* badSamples = nullptr);

  int width() const { return width_; }
  int height() const { return height_; }
  uint32_t pixels() const { return static_cast<uint32_t>(width_) * height_; }

 private:
  Context& ctx_;
  int width_, height_;
  cl::Buffer film_, bad_;
  cl::Kernel accumulate_;
};

}  // namespace pr
