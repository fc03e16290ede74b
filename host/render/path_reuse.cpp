#include "render/path_reuse.h"

#include <algorithm>
#include <numeric>

#include "cl/kernel_binding.h"
#include "util/check.h"
#include "render/counter_lanes.h"
#include "render/kernel_programs.h"
#include "render/path_tracer.h"
#include "shared/reuse.h"
#include "shared/splat.h"
#include "util/error.h"
#include "util/interrupt.h"

namespace pr {

namespace {

// A counter of the light paths (the same on every device that holds them).
void setLightPathCounter(FrameStats* stats, const char* key, uint64_t value) {
  stats->counters[key] = value;
  stats->lightPathCounters.insert(key);
}

}  // namespace

std::string PathReuse::describe() const {
  return "arena " + std::to_string(slots_) + " slots x " + std::to_string(stride_) +
         " vertices = " + std::to_string(arenaBytes() >> 20) + " MiB";
}

cl_uint PathReuse::historySlotOffset(const dev::ReuseParams& rp) const {
  // With a history, the light paths shift by a random offset every historyPeriod frames of the
  // RNG's frame key, so that the reservoir meets new candidates; between shifts the noise stays
  // put (less flicker). Without one, the fixed mapping.
  if (settings_.connect.historyCap == 0) return 0;
  const uint32_t key = rp.frame / uint32_t(settings_.connect.historyPeriod);
  return dev::pr_hash_u32(rp.seed ^ dev::pr_hash_u32(key ^ 0x534c4f54u)) % rp.slots;
}

PathReuse::PathReuse(Context& ctx, GpuScene& scene, Film& film, const PathReuseSettings& settings)
    : ctx_(ctx), scene_(scene), film_(film), settings_(settings) {
  if (settings_.maxDepth < 2) throw InputError("--max-depth: path reuse needs at least 2");
  if (settings_.connect.pathsPerPixel < 1 || settings_.connect.pathsPerPixel > 64)
    throw InputError("--paths-per-pixel: must be 1 to 64");
  PR_CHECK(settings_.connect.lightTracing.has_value() && settings_.connect.resample >= 0 &&
           settings_.connect.arenaSlots >= 0);  // resolved by the session
  lightTracing_ = *settings_.connect.lightTracing;
  slots_ = settings_.connect.arenaSlots ? uint32_t(settings_.connect.arenaSlots)
                                        : defaultLightPaths(film.pixels());
  stride_ = static_cast<uint32_t>(settings_.maxDepth - 1);
  const std::string opts = scene.buildOptions();
  invalidate_ = kargs::kernel<kargs::InvalidateArgs>(ctx, "reuse/invalidate.cl", opts);
  lightTrace_ = kargs::kernel<kargs::LightTraceArgs>(ctx, "reuse/light_trace.cl", opts);
  eyeHit_ = kargs::kernel<kargs::EyeHitArgs>(ctx, "reuse/eye_hit.cl", opts);
  // With eye paths, connect traces no ray: its terms go to connect_shadow (kernels/reuse).
  Techniques techniques;
  techniques.eyePaths = settings_.connect.eyePaths;
  connect_ = kargs::kernel<kargs::ConnectArgs>(ctx, "reuse/connect.cl",
                                               opts + techniqueBuildOptions(techniques));
  if (settings_.connect.eyePaths)
    connectShadow_ = kargs::kernel<kargs::ConnectShadowArgs>(ctx, "reuse/connect_shadow.cl", opts);
  // Strategy T's weights need the eye paths' ratios (kernels/shared/eye_paths.h).
  PR_CHECK(!lightTracing_ || settings_.connect.eyePaths);
  if (lightTracing_)
    cameraSplat_ = kargs::kernel<kargs::CameraSplatArgs>(ctx, "reuse/camera_splat.cl", opts);
  auto alloc = [&](const char* name, uint64_t bytes) {
    bytes_ += bytes;
    cl::Buffer b = ctx_.allocate(name, bytes);
    ctx_.zero(b, bytes);
    return b;
  };
  // The arena first: the largest buffer, so a too large request fails naming it.
  vertices_ = alloc("light vertex arena", uint64_t(slots_) * stride_ * sizeof(dev::LightVertex));
  // With eye paths, L's weights' light side beside each vertex; else one unread element.
  ratios_ = alloc("eye-path ratios", (settings_.connect.eyePaths ? uint64_t(slots_) * stride_ : 1) *
                                         sizeof(dev::EyePathRatio));
  headers_ = alloc("path headers", uint64_t(slots_) * sizeof(dev::PathHeader));
  list_ = alloc("invalid slot list", uint64_t(slots_) * 4);
  allSlots_ = alloc("slot list", uint64_t(slots_) * 4);
  std::vector<uint32_t> all(slots_);
  std::iota(all.begin(), all.end(), 0u);
  CL_CHECK(ctx_.queue().enqueueWriteBuffer(allSlots_, CL_TRUE, 0, all.size() * 4, all.data()));
  eye_ = alloc("eye vertices", uint64_t(film.pixels()) * sizeof(dev::EyeVertex));
  radiance_ = alloc("sample radiance", uint64_t(film.pixels()) * 16);
  counters_ = alloc("reuse counters", counterBytes(dev::PR_C_ROW));
  splat_ =
      alloc("camera splats", (lightTracing_ ? uint64_t(film.pixels()) : 1) * PR_SPLAT_WORDS * 4);
  // Without a history, one element each: the kernels take them but never read them.
  const bool history = settings_.connect.historyCap > 0;
  changed_ = alloc("changed slot stamps", uint64_t(history ? slots_ : 1) * 4);
  const uint64_t records = history ? uint64_t(film.pixels()) * settings_.spp : 1;
  history_ = alloc("connection history", records * sizeof(dev::ConnectionHistory));
  if (settings_.connect.eyePaths) {
    // Per pixel sample: L's connections at x, each a term (at most C per stored vertex k >= 1)
    // and their sum's end, the history's one term, a reservoir's terms and their sum's end.
    recordCap_ = uint32_t(settings_.connect.pathsPerPixel) * (stride_ - 1) + 1 + 1 +
                 uint32_t(settings_.connect.resample) + 1;
    const uint64_t perSample = uint64_t(recordCap_) * sizeof(dev::ShadowRay);
    recordPixels_ = static_cast<uint32_t>(
        std::clamp<uint64_t>(settings_.connectRecordBytes / perSample, 1, film.pixels()));
  }
  records_ =
      alloc("connection records",
            std::max<uint64_t>(uint64_t(recordPixels_) * recordCap_, 1) * sizeof(dev::ShadowRay));
  recordCounts_ = alloc("connection record counts", uint64_t(recordPixels_) * 4);
  if (settings_.connect.eyePaths) {
    PathTracerSettings pt;
    pt.spp = settings_.spp;
    pt.maxDepth = settings_.maxDepth;
    pt.seed = settings_.seed;
    pt.fixedNoise = settings_.fixedNoise;
    pt.pathsPerPixel = uint32_t(settings_.connect.pathsPerPixel);
    pt.lightTracingSlots = lightTracing_ ? slots_ : 0;
    pt.resample = settings_.resamplePaths;
    pt.wavefrontPixels = settings_.wavefrontPixels;
    eyePaths_ = std::make_unique<PathTracer>(ctx, scene, film, pt);
    bytes_ += eyePaths_->deviceBytes();
  }
}

dev::ReuseParams PathReuse::frameParams(int64_t frame) const {
  dev::ReuseParams rp{};
  rp.seed = settings_.seed;
  rp.slots = slots_;
  rp.stride = stride_;
  rp.max_depth = static_cast<uint32_t>(settings_.maxDepth);
  rp.paths_per_pixel = cl_uint(settings_.connect.pathsPerPixel);
  rp.spp = static_cast<uint32_t>(settings_.spp);
  rp.pixel_count = film_.end();  // the bound of the film's pixels [first, end)
  rp.frame = settings_.fixedNoise ? 0u : rngFrameKey(frame);  // RNG key only
  rp.clamp = settings_.connect.clamp;
  // With eye paths, strategy E's paths are the path tracer's.
  rp.mis_threshold = settings_.connect.eyePaths ? 0.0f : settings_.connect.mis;
  rp.eye_paths = settings_.connect.eyePaths ? 1u : 0u;
  // pt_shade weighs the eye paths with the same count (PathTracer::resampleParams).
  rp.eye_count = settings_.resamplePaths.enabled ? settings_.resamplePaths.misCount : 1.0f;
  PR_CHECK(settings_.connect.resample <= PR_MAX_CONNECTIONS);  // the CLI allows 1-4
  rp.resample = cl_uint(settings_.connect.resample);
  rp.trace_total = scene_.traceTotalPower();
  rp.scene_radius = scene_.sceneRadius();
  rp.cx = scene_.sceneCentre().x, rp.cy = scene_.sceneCentre().y, rp.cz = scene_.sceneCentre().z;

  return rp;
}

void PathReuse::renderFrame(int64_t frame, const dev::CameraParams& camera, FrameStats* stats) {
  const Clock::time_point start = Clock::now();
  StageTimer timer;
  ctx_.zero(counters_, counterBytes(dev::PR_C_ROW));
  dev::ReuseParams rp = frameParams(frame);
  if (lightTracing_)
    rp.lt_scale =
        lightTracingScale(camera, slots_, settings_.spp, uint32_t(settings_.connect.pathsPerPixel));

  // 1. Which slots must be traced again. With a connection history, retrace learns the same
  // changed slots as reuse (invalidate marks them and leaves the arena alone), so that the
  // histories, and the frames, agree.
  const kargs::SceneArgs sceneArgs = scene_.kernelArgs();
  const bool history = settings_.connect.historyCap > 0;
  const cl_uint frameStamp = history ? ++frames_ : 0;
  cl_uint toTrace = slots_;
  const cl::Buffer* list = &allSlots_;
  if (!first_ && (!settings_.retraceAll || history)) {
    kargs::InvalidateArgs a;
    kargs::setScene(&a, sceneArgs);
    a.rp = rp;
    a.test_segments = scene_.anyInstanceMoved() ? 1 : 0;
    a.headers = headers_;
    a.vertices = vertices_;
    a.list = list_;
    a.counters = counters_;
    a.mark_only = settings_.retraceAll ? 1 : 0;
    a.frame_stamp = frameStamp;
    a.changed = changed_;
    a.set(invalidate_);
    ctx_.launch1D(invalidate_, slots_, "invalidate", &timer);
    if (!settings_.retraceAll) {
      CL_CHECK(ctx_.queue().enqueueReadBuffer(counters_, CL_TRUE, dev::PR_C_LIST * 4, 4, &toTrace));
      PR_CHECK(toTrace <= slots_);  // invalidate lists each slot at most once
      list = &list_;
    }
  }
  first_ = false;

  // 2. Trace them.
  if (toTrace > 0) {
    kargs::LightTraceArgs a;
    kargs::setScene(&a, sceneArgs);
    a.rp = rp;
    a.trace_cdf = scene_.traceCdf();
    a.headers = headers_;
    a.vertices = vertices_;
    a.ratios = ratios_;
    a.list = *list;
    a.list_count = toTrace;
    a.counters = counters_;
    a.set(lightTrace_);
    ctx_.launch1D(lightTrace_, toTrace, "light_trace", &timer);
  }

  // Once per frame, by the device with the first pass (several devices add their films), before
  // the passes: the film's sum is then the splats and the samples in pass order, as one device
  // adds them, wherever the passes after the first device's run.
  // With a time limit (one device) the splats are kept, to be scaled to the passes rendered.
  const bool splat = lightTracing_ && passBegin_ == 0;
  if (splat) splatToCamera(camera, rp, sceneArgs, &timer);
  const int passes = tracePasses(frame, camera, rp, sceneArgs, frameStamp, start, &timer);
  if (passes < 0) return;
  if (splat && film_.adaptive()) {
    // Each pixel's count of samples times 1/spp of strategy T's estimate (kernels/accumulate.cl).
    film_.addSplats(splat_, &timer, 1.0f / float(settings_.spp), true, true);
  } else if (splat && timeLimit_ > 0.0) {
    // They were added for spp samples per pixel; the film's mean divides by `passes`.
    const int spp = settings_.spp;
    if (passes < spp) film_.addSplats(splat_, &timer, float(passes - spp) / float(spp));
    ctx_.zero(splat_, uint64_t(film_.pixels()) * PR_SPLAT_WORDS * 4);
  }
  if (stats) stats->passes = passes;
  if (eyePaths_) eyePaths_->reportRays(stats);
  report(&timer, toTrace, stats);
}

void PathReuse::splatToCamera(const dev::CameraParams& camera, const dev::ReuseParams& rp,
                              const kargs::SceneArgs& sceneArgs, StageTimer* timer) {
  kargs::CameraSplatArgs a;
  kargs::setScene(&a, sceneArgs);
  a.rp = rp;
  a.cam = camera;
  a.headers = headers_;
  a.vertices = vertices_;
  a.ratios = ratios_;
  a.splat = splat_;
  a.first = film_.first();
  a.end = film_.end();
  a.film_scale = float(settings_.spp);  // the film's mean divides by its samples
  a.counters = counters_;
  a.cam_steps = scene_.cameraSteps();
  a.cam_step_count = scene_.motionSteps();
  a.set(cameraSplat_);
  ctx_.launch1D(cameraSplat_, slots_, "camera_splat", timer);
  // Under --noise-threshold they wait for the pixels' counts (renderFrame).
  if (!film_.adaptive()) film_.addSplats(splat_, timer, 1.0f, timeLimit_ <= 0.0);
}

int PathReuse::tracePasses(int64_t frame, const dev::CameraParams& camera,
                           const dev::ReuseParams& rp, const kargs::SceneArgs& sceneArgs,
                           cl_uint frameStamp, Clock::time_point start, StageTimer* timer) {
  // 3. Per sample: first hits, then connections, then the film.
  // `sample` changes per pass.
  kargs::EyeHitArgs eh;
  kargs::setScene(&eh, sceneArgs);
  eh.rp = rp;
  eh.cam = camera;
  eh.eye = eye_;
  eh.radiance = radiance_;
  eh.counters = counters_;
  eh.budget = film_.budget();
  eh.set(eyeHit_);
  kargs::ConnectArgs cn;
  kargs::setScene(&cn, sceneArgs);
  cn.rp = rp;
  cn.cam = camera;
  cn.eye = eye_;
  cn.headers = headers_;
  cn.vertices = vertices_;
  cn.radiance = radiance_;
  cn.counters = counters_;
  cn.history_cap = cl_uint(settings_.connect.historyCap);
  cn.slot_offset = historySlotOffset(rp);
  cn.frame_stamp = frameStamp;
  cn.changed = changed_;
  cn.history = history_;
  cn.ratios = ratios_;
  cn.records = records_;
  cn.record_counts = recordCounts_;
  cn.record_cap = recordCap_;
  cn.cam_steps = scene_.cameraSteps();
  cn.cam_step_count = scene_.motionSteps();
  cn.set(connect_, kargs::kScene | kargs::kFrame);
  kargs::ConnectShadowArgs cs;
  if (eyePaths_) {
    kargs::setScene(&cs, sceneArgs);
    cs.records = records_;
    cs.record_counts = recordCounts_;
    cs.record_cap = recordCap_;
    cs.radiance = radiance_;
    cs.counters = counters_;
    cs.seed = rp.seed;  // the samples' times (--shutter), as connect keys them
    cs.frame = rp.frame;
    cs.set(connectShadow_, kargs::kScene | kargs::kFrame);
  }
  if (eyePaths_) eyePaths_->beginFrame(frame, camera, sceneArgs, radiance_, eye_);
  const cl_uint first = film_.first(), n = film_.end();
  int passes = 0, s = passBegin_;
  for (; s < passEnd(settings_.spp) && film_.passWanted(s); ++s) {
    // With eye paths, the path tracer's pass writes the sample's radiance and its first eye
    // vertex, where eye_hit would.
    const cl_uint masked = film_.beginPass(s, timer);
    if (eyePaths_) {
      eyePaths_->tracePass(s, masked, timer);
    } else {
      eh.sample = cl_uint(s);
      eh.masked = masked;
      eh.set(eyeHit_, kargs::kPass);
      ctx_.launch1D(eyeHit_, first, n, "eye_hit", timer);
    }
    cn.sample = cs.sample = cl_uint(s);
    // A masked pass connects its listed pixels alone.
    cn.pixels = cs.pixels = film_.pixelList();
    cn.listed = cs.listed = masked;
    cn.list_count = cs.list_count = film_.listCount();
    const cl_uint lo = masked ? 0 : first, hi = masked ? film_.listCount() : n;
    // Without eye paths connect traces its rays itself (one launch); with them, each launch's
    // terms are traced by connect_shadow before the next launch reuses the records.
    const cl_uint chunk = eyePaths_ ? recordPixels_ : hi - lo;
    for (cl_uint c0 = lo; c0 < hi; c0 += chunk) {
      cn.record_first = cs.record_first = c0;
      cn.record_end = cs.record_end = std::min(hi, c0 + chunk);
      cn.set(connect_, kargs::kPass);
      ctx_.launch1D(connect_, c0, cn.record_end, "connect", timer);
      if (!eyePaths_) continue;
      cs.set(connectShadow_, kargs::kPass);
      ctx_.launch1D(connectShadow_, c0, cs.record_end, "connect_shadow", timer);
    }
    film_.accumulate(radiance_, s, timer);
    // Wait for each pass, so that an interrupt stops a frame of many samples within one pass.
    ctx_.finish();
    if (interrupted()) return -1;
    ++passes;
    if (outOfTime(start)) break;
  }
  if (eyePaths_ && !film_.passWanted(s)) eyePaths_->skipPasses(s);
  return passes;
}

void PathReuse::report(StageTimer* timer, cl_uint toTrace, FrameStats* stats) {
  const auto c = readCounters<dev::PR_C_COUNT>(ctx_, counters_, dev::PR_C_ROW);
  PR_CHECK(c[dev::PR_C_RECORD_OVERFLOW] == 0);  // recordCap_ bounds connect's terms
  auto times = timer->collect();
  if (!stats) return;
  for (const auto& [k, v] : times) stats->stageSeconds[k] += v;
    // Every counter where kernels/shared/reuse.h's list says.
#define PR_REPORT_rays(key, value) stats->rays[key] += value;
#define PR_REPORT_counters(key, value) stats->counters[key] = value;
#define PR_REPORT_paths(key, value) setLightPathCounter(stats, key, value);
#define PR_REPORT_internal(key, value)
#define PR_REPORT(name, group, key) PR_REPORT_##group(key, c[dev::PR_C_##name])
  PR_REUSE_COUNTERS(PR_REPORT)
#undef PR_REPORT
#undef PR_REPORT_rays
#undef PR_REPORT_counters
#undef PR_REPORT_paths
#undef PR_REPORT_internal
  setLightPathCounter(stats, "slots", slots_);
  setLightPathCounter(stats, "slots_retraced", toTrace);
  setLightPathCounter(stats, "slots_invalidated",
                      settings_.retraceAll ? slots_ : c[dev::PR_C_LIST]);
  setLightPathCounter(stats, "slots_reused", slots_ - toTrace);
  setLightPathCounter(stats, "arena_bytes", arenaBytes());
}

void PathReuse::readArena(std::vector<dev::PathHeader>* headers,
                          std::vector<dev::LightVertex>* vertices) {
  headers->resize(slots_);
  vertices->resize(size_t(slots_) * stride_);
  CL_CHECK(ctx_.queue().enqueueReadBuffer(
      headers_, CL_TRUE, 0, headers->size() * sizeof(dev::PathHeader), headers->data()));
  CL_CHECK(ctx_.queue().enqueueReadBuffer(
      vertices_, CL_TRUE, 0, vertices->size() * sizeof(dev::LightVertex), vertices->data()));
}

}  // namespace pr
