#include "render/path_tracer.h"

#include <chrono>

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
}

void PathTracer::renderFrame(int frame, const dev::CameraParams& camera, FrameStats* stats) {
  StageTimer timer;
  const cl_uint n = film_.pixels();
  const cl_uint rngFrame = settings_.fixedNoise ? 0 : cl_uint(frame);
  ctx_.zero(rays_, 16);
  const cl_uint first = GpuScene::kArgCount;
  scene_.setKernelArgs(extend_, 0);
  scene_.setKernelArgs(shade_, 0);
  scene_.setKernelArgs(shadow_, 0);
  CL_CHECK(extend_.setArg(first + 0, states_));
  CL_CHECK(extend_.setArg(first + 1, hits_));
  CL_CHECK(extend_.setArg(first + 2, rays_));
  CL_CHECK(extend_.setArg(first + 3, n));
  CL_CHECK(shade_.setArg(first + 0, states_));
  CL_CHECK(shade_.setArg(first + 1, hits_));
  CL_CHECK(shade_.setArg(first + 2, radiance_));
  CL_CHECK(shade_.setArg(first + 3, shadows_));
  CL_CHECK(shade_.setArg(first + 4, n));
  CL_CHECK(shade_.setArg(first + 5, settings_.seed));
  CL_CHECK(shade_.setArg(first + 6, rngFrame));
  CL_CHECK(shade_.setArg(first + 8, cl_uint(settings_.maxDepth)));
  CL_CHECK(shadow_.setArg(first + 0, radiance_));
  CL_CHECK(shadow_.setArg(first + 1, shadows_));
  CL_CHECK(shadow_.setArg(first + 2, rays_));
  CL_CHECK(shadow_.setArg(first + 3, n));
  CL_CHECK(generate_.setArg(0, camera));
  CL_CHECK(generate_.setArg(1, settings_.seed));
  CL_CHECK(generate_.setArg(2, rngFrame));
  CL_CHECK(generate_.setArg(4, states_));
  CL_CHECK(generate_.setArg(5, radiance_));
  CL_CHECK(generate_.setArg(6, n));
  for (int s = 0; s < settings_.spp; ++s) {
    CL_CHECK(generate_.setArg(3, cl_uint(s)));
    CL_CHECK(shade_.setArg(first + 7, cl_uint(s)));
    ctx_.launch1D(generate_, n, "generate", &timer);
    for (int d = 0; d < settings_.maxDepth; ++d) {
      ctx_.launch1D(extend_, n, "extend", &timer);
      ctx_.launch1D(shade_, n, "shade", &timer);
      ctx_.launch1D(shadow_, n, "shadow", &timer);
    }
    film_.accumulate(radiance_, n, &timer);
    // Wait for each pass, so that an interrupt stops a frame of many samples within one pass.
    ctx_.finish();
    if (interrupted()) return;
  }
  cl_uint rays[4] = {0, 0, 0, 0};
  CL_CHECK(ctx_.queue().enqueueReadBuffer(rays_, CL_TRUE, 0, 16, rays));
  if (stats) {
    for (const auto& [k, v] : timer.collect()) stats->stageSeconds[k] += v;
    stats->rays["camera"] += rays[0];
    stats->rays["bounce"] += rays[1];
    stats->rays["shadow"] += rays[2];
  } else {
    timer.collect();
  }
}

}  // namespace pr
