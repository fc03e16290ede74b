#include "render/film.h"

#include <vector>

namespace pr {

Film::Film(Context& ctx, int width, int height) : ctx_(ctx), width_(width), height_(height) {
  film_ = ctx_.allocate("film", uint64_t(pixels()) * 16);
  bad_ = ctx_.allocate("bad sample counter", 4);
  accumulate_ = ctx_.kernel("accumulate.cl", "accumulate");
  clear();
}

void Film::clear() {
  ctx_.zero(film_, uint64_t(pixels()) * 16);
  ctx_.zero(bad_, 4);
}

void Film::accumulate(const cl::Buffer& radiance, uint32_t count, StageTimer* timer) {
  CL_CHECK(accumulate_.setArg(0, radiance));
  CL_CHECK(accumulate_.setArg(1, film_));
  CL_CHECK(accumulate_.setArg(2, bad_));
  CL_CHECK(accumulate_.setArg(3, count));
  CL_CHECK(accumulate_.setArg(4, pixels()));
  ctx_.launch1D(accumulate_, count, "accumulate", timer);
}

Image Film::read(uint64_t* badSamples) {
  std::vector<float> sums(size_t(pixels()) * 4);
  CL_CHECK(ctx_.queue().enqueueReadBuffer(film_, CL_TRUE, 0, sums.size() * 4, sums.data()));
  cl_uint bad = 0;
  CL_CHECK(ctx_.queue().enqueueReadBuffer(bad_, CL_TRUE, 0, 4, &bad));
  if (badSamples) *badSamples = bad;
  Image img(width_, height_);
  for (size_t i = 0; i < pixels(); ++i) {
    const float n = sums[i * 4 + 3];
    for (int c = 0; c < 3; ++c) img.rgba[i * 4 + c] = n > 0.0f ? sums[i * 4 + c] / n : 0.0f;
    img.rgba[i * 4 + 3] = 1.0f;
  }
  return img;
}

}  // namespace pr
