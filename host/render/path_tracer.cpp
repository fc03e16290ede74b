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
  generate_ = kargs::kernel<kargs::PtGenerateArgs>(ctx, "pathtrace/generate.cl", opts);
  extend_ = kargs::kernel<kargs::PtExtendArgs>(ctx, "pathtrace/extend.cl", opts);
  shade_ = kargs::kernel<kargs::PtShadeArgs>(ctx, "pathtrace/shade.cl", opts);
  shadow_ = kargs::kernel<kargs::PtShadowArgs>(ctx, "pathtrace/shadow.cl", opts);
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
  rays_ = alloc("ray counters", dev::PR_PT_COUNT * 4);
  noEye_ = alloc("no eye vertices", 64);
}

void PathTracer::beginFrame(int frame, const dev::CameraParams& camera,
                            const kargs::SceneArgs& sceneArgs, const cl::Buffer& radiance,
                            const cl::Buffer& eye) {
  // The film's pixels [first, n) only; buffers are indexed by pixel over the whole image.
  const cl_uint n = film_.end();
  const cl_uint rngFrame = settings_.fixedNoise ? 0 : cl_uint(frame);
  ctx_.zero(rays_, dev::PR_PT_COUNT * 4);
  kargs::PtExtendArgs ex;
  kargs::setScene(&ex, sceneArgs);
  ex.states = states_;
  ex.hits = hits_;
  ex.rays = rays_;
  ex.count = n;
  ex.set(extend_);
  kargs::setScene(&shadeArgs_, sceneArgs);
  shadeArgs_.states = states_;
  shadeArgs_.hits = hits_;
  shadeArgs_.radiance = radiance;
  shadeArgs_.shadows = shadows_;
  shadeArgs_.count = n;
  shadeArgs_.seed = settings_.seed;
  shadeArgs_.frame = rngFrame;
  shadeArgs_.max_depth = cl_uint(settings_.maxDepth);
  shadeArgs_.light_paths = cl_uint(settings_.lightPaths);
  shadeArgs_.trace_cdf = scene_.traceCdf();
  shadeArgs_.trace_total = scene_.traceTotalPower();
  shadeArgs_.eye = eye;
  shadeArgs_.set(shade_);
  kargs::PtShadowArgs sh;
  kargs::setScene(&sh, sceneArgs);
  sh.radiance = radiance;
  sh.shadows = shadows_;
  sh.rays = rays_;
  sh.count = n;
  sh.set(shadow_);
  generateArgs_.cam = camera;
  generateArgs_.seed = settings_.seed;
  generateArgs_.frame = rngFrame;
  generateArgs_.states = states_;
  generateArgs_.radiance = radiance;
  generateArgs_.count = n;
  generateArgs_.eye = eye;
  generateArgs_.write_eye = settings_.lightPaths > 0 ? 1 : 0;
  generateArgs_.set(generate_);
}

void PathTracer::tracePass(int sample, StageTimer* timer) {
  const cl_uint first = film_.first(), n = film_.end();
  // `sample` is the only argument that changes between passes.
  generateArgs_.sample = shadeArgs_.sample = cl_uint(sample);
  generateArgs_.set(generate_, kargs::kPass);
  shadeArgs_.set(shade_, kargs::kPass);
  ctx_.launch1D(generate_, first, n, "generate", timer);
  for (int d = 0; d < settings_.maxDepth; ++d) {
    ctx_.launch1D(extend_, first, n, "extend", timer);
    ctx_.launch1D(shade_, first, n, "shade", timer);
    ctx_.launch1D(shadow_, first, n, "shadow", timer);
  }
}

void PathTracer::reportRays(FrameStats* stats) {
  cl_uint rays[dev::PR_PT_COUNT] = {};
  CL_CHECK(ctx_.queue().enqueueReadBuffer(rays_, CL_TRUE, 0, sizeof rays, rays));
  if (!stats) return;
#define PR_PT_REPORT(name, key) stats->rays[key] += rays[dev::PR_PT_##name];
  PR_PT_COUNTERS(PR_PT_REPORT)
#undef PR_PT_REPORT
}

void PathTracer::renderFrame(int frame, const dev::CameraParams& camera, FrameStats* stats) {
  StageTimer timer;
  beginFrame(frame, camera, scene_.kernelArgs(), radiance_, noEye_);
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
