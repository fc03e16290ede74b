#include "render/film.h"

#include <algorithm>
#include <vector>

#include "cl/kernel_binding.h"
#include "util/check.h"

namespace pr {

Film::Film(Context& ctx, int width, int height)
    : ctx_(ctx), width_(width), height_(height), rowEnd_(height) {
  film_ = ctx_.allocate("film", uint64_t(pixels()) * 16);
  bad_ = ctx_.allocate("bad sample counter", 4);
  accumulate_ = kargs::kernel<kargs::AccumulateArgs>(ctx_, "accumulate.cl");
  splatFilm_ = kargs::kernel<kargs::SplatFilmArgs>(ctx_, "accumulate.cl");
  // Without --noise-threshold, one unread word each.
  budget_ = ctx_.allocate("pixel budgets", 4);
  ctx_.zero(budget_, 4);
  list_ = ctx_.allocate("pass pixel list", 4);
  ctx_.zero(list_, 4);
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
  if (adaptive()) {
    ctx_.zero(odd_, uint64_t(pixels()) * 16);
    ctx_.zero(oddBad_, 4);
  }
}

void Film::setAdaptive(const AdaptiveSettings& settings) {
  PR_CHECK(settings.threshold > 0.0f && settings.pilot >= 2 && settings.pilot <= settings.spp);
  adaptive_ = settings;
  ctx_.release("pixel budgets", 4);  // the unread words budget_ and list_ were
  ctx_.release("pass pixel list", 4);
  odd_ = ctx_.allocate("odd pass sums", uint64_t(pixels()) * 16);
  oddBad_ = ctx_.allocate("odd pass bad samples", 4);
  budget_ = ctx_.allocate("pixel budgets", uint64_t(pixels()) * 4);
  list_ = ctx_.allocate("pass pixel list", uint64_t(pixels()) * 4);
  ctx_.zero(list_, uint64_t(pixels()) * 4);
  listSize_ = ctx_.allocate("pass pixel count", 4);
  plan_ = kargs::kernel<kargs::AdaptivePlanArgs>(ctx_, "adaptive.cl");
  listKernel_ = kargs::kernel<kargs::AdaptiveListArgs>(ctx_, "adaptive.cl");
  // No pass is masked before the first plan; budgets of spp until then.
  const std::vector<uint32_t> all(pixels(), uint32_t(settings.spp));
  CL_CHECK(ctx_.queue().enqueueWriteBuffer(budget_, CL_TRUE, 0, all.size() * 4, all.data()));
  clear();
}

cl_uint Film::beginPass(int sample, StageTimer* timer) {
  if (!adaptive() || sample < adaptive_.pilot) return 0u;
  if (sample == adaptive_.pilot) {
    kargs::AdaptivePlanArgs a;
    a.film = film_;
    a.odd = odd_;
    a.budget = budget_;
    a.width = cl_uint(width_);
    a.first = first();
    a.end = end();
    a.radius = cl_uint(adaptive_.radius);
    a.pilot = cl_uint(adaptive_.pilot);
    a.spp = cl_uint(adaptive_.spp);
    a.threshold = adaptive_.threshold;
    a.max_budget = listSize_;
    a.set(plan_);
    ctx_.zero(listSize_, 4);
    ctx_.launch1D(plan_, first(), end(), "adaptive_plan", timer);
    cl_uint most = 0;
    CL_CHECK(ctx_.queue().enqueueReadBuffer(listSize_, CL_TRUE, 0, 4, &most));
    maxBudget_ = std::max(adaptive_.pilot, int(most));
  }
  ctx_.zero(listSize_, 4);
  kargs::AdaptiveListArgs a;
  a.budget = budget_;
  a.sample = cl_uint(sample);
  a.end = end();
  a.pixels = list_;
  a.count = listSize_;
  a.set(listKernel_);
  ctx_.launch1D(listKernel_, first(), end(), "adaptive_list", timer);
  CL_CHECK(ctx_.queue().enqueueReadBuffer(listSize_, CL_TRUE, 0, 4, &listCount_));
  PR_CHECK(listCount_ <= end() - first());
  return 1u;
}

void Film::launchAccumulate(const cl::Buffer& radiance, const cl::Buffer& film,
                            const cl::Buffer& bad, cl_uint listed, StageTimer* timer) {
  kargs::AccumulateArgs a;
  a.radiance = radiance;
  a.film = film;
  a.bad_samples = bad;
  a.count = listed ? listCount_ : end();
  a.pixel_count = pixels();
  a.pixels = list_;
  a.listed = listed;
  a.list_count = listCount_;
  a.set(accumulate_);
  ctx_.launch1D(accumulate_, listed ? 0 : first(), a.count, "accumulate", timer);
}

void Film::accumulate(const cl::Buffer& radiance, int sample, StageTimer* timer) {
  const cl_uint masked = adaptive() && sample >= adaptive_.pilot ? 1u : 0u;
  launchAccumulate(radiance, film_, bad_, masked, timer);
  // The pilot's odd passes once more, apart (their non-finite samples counted apart too).
  if (adaptive() && sample < adaptive_.pilot && sample % 2 == 1)
    launchAccumulate(radiance, odd_, oddBad_, 0u, timer);
}

void Film::addSplats(const cl::Buffer& splat, StageTimer* timer, float scale, bool clear,
                     bool byCount) {
  kargs::SplatFilmArgs a;
  a.splat = splat;
  a.film = film_;
  a.scale = scale;
  a.clear = clear ? 1u : 0u;
  a.by_count = byCount ? 1u : 0u;
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

std::vector<float> Film::readRows(Image* image, uint64_t* badSamples) {
  PR_CHECK(image->width == width_ && image->height == height_);
  std::vector<float> sums = readSums(badSamples);
  mean(sums.data(), sums.size() / 4, image->rgba.data() + size_t(first()) * 4);
  return sums;
}

}  // namespace pr
