#include "render/path_tracer.h"

#include <chrono>

#include "cl/kernel_args.h"
#include "shared/path_state.h"
#include "util/interrupt.h"

namespace pr {

PathTracer::PathTracer(Context& ctx, GpuScene& scene, Film& film,
                       const PathTracerSettings& settings)
    : ctx_(ctx), scene_(scene), film_(film), settings_(settings) {
  const std::string opts = scene.buildOptions();
  generate_ = ctx.kernel("pathtrace/generate.cl", "pt_generate", opts);
  extend_ = ctx.kernel("pathtrace/extend.cl", "pt_extend", opts);
  shade_ = ctx.kernel("pathtrace/shade.cl", "pt_shade", opts);
  shadow_ = ctx.kernel("pathtrace/shadow.cl", "pt_shadow", opts);
  const uint64_t n = film.pixels();
  auto alloc = [&](const char* name, uint64_t bytes) {
    bytes_ += bytes;
    cl::Buffer b = ctx_.allocate(name, bytes);
    ctx_.zero(b, bytes);
    return b;
  };
  states_ = alloc("path states", n * sizeof(dev::PathState));
  hits_ = alloc("path hits", n * sizeof(dev::Hit));
  radiance_ = alloc("sample radiance", n * 16);
  shadows_ = alloc("shadow rays", n * sizeof(dev::ShadowRay));
  rays_ = alloc("ray counters", 16);
  noEye_ = alloc("no eye vertices", 64);
}

void PathTracer::beginFrame(int frame, const dev::CameraParams& camera, const cl::Buffer& radiance,
                            const cl::Buffer& eye) {
  // The film's pixels [first, n) only; buffers are indexed by pixel over the whole image.
  const cl_uint n = film_.end();
  const cl_uint rngFrame = settings_.fixedNoise ? 0 : cl_uint(frame);
  ctx_.zero(rays_, 16);
  // Each kernel's own arguments follow the scene's (PR_SCENE_PARAMS); `sample` changes per pass.
  setKernelArgs(extend_, scene_.setKernelArgs(extend_, 0), states_, hits_, rays_, n);
  shadeSample_ = setKernelArgs(shade_, scene_.setKernelArgs(shade_, 0), states_, hits_, radiance,
                               shadows_, n, settings_.seed, rngFrame);
  setKernelArgs(shade_, shadeSample_ + 1, cl_uint(settings_.maxDepth),
                cl_uint(settings_.lightPaths), scene_.traceCdf(), scene_.traceTotalPower(), eye);
  setKernelArgs(shadow_, scene_.setKernelArgs(shadow_, 0), radiance, shadows_, rays_, n);
  generateSample_ = setKernelArgs(generate_, 0, camera, settings_.seed, rngFrame);
  setKernelArgs(generate_, generateSample_ + 1, states_, radiance, n, eye,
                cl_uint(settings_.lightPaths > 0 ? 1 : 0));
}

void PathTracer::tracePass(int sample, StageTimer* timer) {
  const cl_uint first = film_.first(), n = film_.end();
  CL_CHECK(generate_.setArg(generateSample_, cl_uint(sample)));
  CL_CHECK(shade_.setArg(shadeSample_, cl_uint(sample)));
  ctx_.launch1D(generate_, first, n, "generate", timer);
  for (int d = 0; d < settings_.maxDepth; ++d) {
    ctx_.launch1D(extend_, first, n, "extend", timer);
    ctx_.launch1D(shade_, first, n, "shade", timer);
    ctx_.launch1D(shadow_, first, n, "shadow", timer);
  }
}

void PathTracer::reportRays(FrameStats* stats) {
  cl_uint rays[4] = {0, 0, 0, 0};
  CL_CHECK(ctx_.queue().enqueueReadBuffer(rays_, CL_TRUE, 0, 16, rays));
  if (!stats) return;
  stats->rays["camera"] += rays[0];
  stats->rays["bounce"] += rays[1];
  stats->rays["shadow"] += rays[2];
}

void PathTracer::renderFrame(int frame, const dev::CameraParams& camera, FrameStats* stats) {
  StageTimer timer;
  beginFrame(frame, camera, radiance_, noEye_);
  for (int s = 0; s < settings_.spp; ++s) {
    tracePass(s, &timer);
    film_.accumulate(radiance_, &timer);
    // Wait for each pass, so that an interrupt stops a frame of many samples within one pass.
    ctx_.finish();
    if (interrupted()) return;
  }
  reportRays(stats);
  if (stats) {
    for (const auto& [k, v] : timer.collect()) stats->stageSeconds[k] += v;
  } else {
    timer.collect();
  }
}

}  // namespace pr
