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

// --noise-threshold (docs/design.md, "Adaptive sampling"): every pixel takes the first `pilot`
// passes; then kernels/adaptive.cl gives each its budget of passes in all (pilot to spp) from
// its neighbours' pilot variance, and a pass is taken only where the budget exceeds its index.
struct AdaptiveSettings {
  float threshold = 0.0f;  // relative error; 0: off
  int pilot = 0;           // passes every pixel takes, at least 2
  int spp = 0;
  int radius = 2;  // the neighbourhood whose variance a pixel's budget is planned from
};

class Film {
 public:
  Film(Context& ctx, int width, int height);

  void clear();
  // Adds sample pass `sample`'s radiance (float4 per pixel, indexed by pixel) of the range's
  // pixels that take the pass.
  void accumulate(const cl::Buffer& radiance, int sample, StageTimer* timer);
  // Adds the range's fixed-point splats (kernels/shared/splat.h, 6 words per pixel, indexed by
  // pixel) times `scale` to the sums, not to the counts, and clears them where `clear`. With
  // `byCount`, times each pixel's count as well.
  void addSplats(const cl::Buffer& splat, StageTimer* timer, float scale = 1.0f, bool clear = true,
                 bool byCount = false);

  void setAdaptive(const AdaptiveSettings& settings);
  bool adaptive() const { return adaptive_.threshold > 0.0f; }
  // Called before each sample pass of a frame: plans the budgets once the pilot is done, and
  // says whether the pass is masked (its kernels then take budget() and skip the pixels
  // without one left; PR_ARGS_PIXEL_MASK).
  cl_uint beginPass(int sample, StageTimer* timer);
  const cl::Buffer& budget() const { return budget_; }
  // A masked pass's pixels (PR_ARGS_PIXEL_LIST), made by beginPass, and their count.
  const cl::Buffer& pixelList() const { return list_; }
  cl_uint listCount() const { return listCount_; }
  // Whether any pixel takes pass `sample` (or a later one): false once every budget is spent.
  bool passWanted(int sample) const {
    return !adaptive() || sample <= adaptive_.pilot || sample < maxBudget_;
  }
  // The mean radiance per pixel (alpha 1), and how many samples were non-finite and dropped.
  Image read(uint64_t* badSamples = nullptr);
  // The same for the range's rows only, written into `image` (of the film's size); returns the
  // sums it read (readSums).
  std::vector<float> readRows(Image* image, uint64_t* badSamples = nullptr);
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
  void launchAccumulate(const cl::Buffer& radiance, const cl::Buffer& film, const cl::Buffer& bad,
                        cl_uint listed, StageTimer* timer);

  Context& ctx_;
  int width_, height_;
  int rowBegin_ = 0, rowEnd_ = 0;
  cl::Buffer film_, bad_;
  cl::Kernel accumulate_, splatFilm_;
  AdaptiveSettings adaptive_;
  // The odd pilot passes' sums (as film_), and each pixel's budget (one unread word when off).
  cl::Buffer odd_, oddBad_, budget_;
  cl::Buffer list_, listSize_;
  cl::Kernel plan_, listKernel_;
  cl_uint listCount_ = 0;
  int maxBudget_ = 0;  // the largest budget of the frame's plan
};

}  // namespace pr
