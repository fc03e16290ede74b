#include "render/film.h"

#include <vector>

#include "cl/kernel_args.h"
#include "util/check.h"

namespace pr {

Film::Film(Context& ctx, int width, int height)
    : ctx_(ctx), width_(width), height_(height), rowEnd_(height) {
  film_ = ctx_.allocate("film", uint64_t(pixels()) * 16);
  bad_ = ctx_.allocate("bad sample counter", 4);
  accumulate_ = kargs::kernel<kargs::AccumulateArgs>(ctx_, "accumulate.cl");
  splatFilm_ = kargs::kernel<kargs::SplatFilmArgs>(ctx_, "accumulate.cl");
  clear();
}

void Film::setRows(int rowBegin, int rowEnd) {
  PR_CHECK(0 <= rowBegin && rowBegin <= rowEnd && rowEnd <= height_);
  rowBegin_ = rowBegin;
  rowEnd_ = rowEnd;
}

void Film::clear() {
  ctx_.zero(film_, uint64_t(pixels()) * 16);
  ctx_.zero(bad_, 4);
}

void Film::accumulate(const cl::Buffer& radiance, StageTimer* timer) {
  kargs::AccumulateArgs a;
  a.radiance = radiance;
  a.film = film_;
  a.bad_samples = bad_;
  a.count = end();
  a.pixel_count = pixels();
  a.set(accumulate_);
  ctx_.launch1D(accumulate_, first(), end(), "accumulate", timer);
}

void Film::addSplats(const cl::Buffer& splat, StageTimer* timer, float scale, bool clear) {
  kargs::SplatFilmArgs a;
  a.splat = splat;
  a.film = film_;
  a.scale = scale;
  a.clear = clear ? 1u : 0u;
  a.end = end();
  a.set(splatFilm_);
  ctx_.launch1D(splatFilm_, first(), end(), "splat_film", timer);
}

Image Film::read(uint64_t* badSamples) {
  Image img(width_, height_);
  readRows(&img, badSamples);
  return img;
}

std::vector<float> Film::readSums(uint64_t* badSamples) {
  const size_t n = end() - first();
  std::vector<float> sums(n * 4);
  if (n > 0)
    CL_CHECK(
        ctx_.queue().enqueueReadBuffer(film_, CL_TRUE, size_t(first()) * 16, n * 16, sums.data()));
  cl_uint bad = 0;
  CL_CHECK(ctx_.queue().enqueueReadBuffer(bad_, CL_TRUE, 0, 4, &bad));
  if (badSamples) *badSamples = bad;
  return sums;
}

void Film::mean(const float* sums, size_t n, float* rgba) {
  for (size_t i = 0; i < n; ++i) {
    const float count = sums[i * 4 + 3];
    for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = count > 0.0f ? sums[i * 4 + c] / count : 0.0f;
    rgba[i * 4 + 3] = 1.0f;
  }
}

void Film::readRows(Image* image, uint64_t* badSamples) {
  PR_CHECK(image->width == width_ && image->height == height_);
  const std::vector<float> sums = readSums(badSamples);
  mean(sums.data(), sums.size() / 4, image->rgba.data() + size_t(first()) * 4);
}

}  // namespace pr
