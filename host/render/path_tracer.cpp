#include "render/path_tracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "cl/kernel_binding.h"
#include "render/counter_lanes.h"
#include "render/history_format.h"
#include "render/kernel_programs.h"
#include "shared/path_state.h"
#include "util/check.h"
#include "util/hash.h"
#include "util/interrupt.h"

namespace pr {

PathTracer::PathTracer(Context& ctx, GpuScene& scene, Film& film,
                       const PathTracerSettings& settings)
    : ctx_(ctx), scene_(scene), film_(film), settings_(settings) {
  const std::string opts = scene.buildOptions();
  generate_ = kargs::kernel<kargs::PtGenerateArgs>(ctx, "pathtrace/generate.cl", opts);
  extend_ = kargs::kernel<kargs::PtExtendArgs>(ctx, "pathtrace/extend.cl", opts);
  // Driven by PathReuse (paths per pixel > 0), the eye paths are weighted against its connections.
  Techniques techniques;
  techniques.eyePaths = settings.pathsPerPixel > 0;
  techniques.resample = settings.resample.enabled;
  shade_ = kargs::kernel<kargs::PtShadeArgs>(ctx, "pathtrace/shade.cl",
                                             opts + techniqueBuildOptions(techniques));
  shadow_ = kargs::kernel<kargs::PtShadowArgs>(ctx, "pathtrace/shadow.cl", opts);
  if (settings.resample.enabled)
    resample_ = kargs::kernel<kargs::PtResampleArgs>(ctx, "pathtrace/resample.cl", opts);
  // Temporal reuse rebuilds the previous frame's x_1 on that frame's shapes.
  if (settings.resample.enabled && settings.resample.history > 0) scene.keepPrevious();
  const uint64_t n = film.pixels();
  auto alloc = [&](const char* name, uint64_t bytes) {
    bytes_ += bytes;
    cl::Buffer b = ctx_.allocate(name, bytes);
    ctx_.zero(b, bytes);
    return b;
  };
  PR_CHECK(settings.wavefrontPixels > 0);
  band_ = uint32_t(std::min<uint64_t>(n, settings.wavefrontPixels));
  const uint64_t band = band_;
  states_ = alloc("path states", band * sizeof(dev::PathState));
  hits_ = alloc("path hits", band * sizeof(dev::Hit));
  // Driven by PathReuse (light paths to connect to), the eye paths write its radiance and eye
  // vertices: those of its own are one unread element and none.
  const bool own = settings.pathsPerPixel == 0;
  radiance_ = alloc("sample radiance", (own ? n : 1) * 16);
  shadows_ = alloc("shadow rays", band * sizeof(dev::ShadowRay));
  for (cl::Buffer& q : queues_) q = alloc("path queue", band * 4);
  shadowQueue_ = alloc("shadow queue", band * 4);
  queueSizes_ = alloc("queue sizes", dev::PR_QUEUE_COUNT * 4);
  rays_ = alloc("ray counters", counterBytes(dev::PR_PT_ROW));
  noEye_ = alloc("no eye vertices", 64);
  // Without resampling, one unread element each. The reservoirs span the frame (neighbours and
  // the history read them); a path's track and candidates are its band's.
  const uint64_t rsPixels = settings.resample.enabled ? n : 1;
  const uint64_t rsBand = settings.resample.enabled ? band : 1;
  rsTrack_ = alloc("path tracks", rsBand * sizeof(dev::PathTrack));
  rsRes_ = alloc("path reservoirs", rsPixels * sizeof(dev::PathReservoir));
  rsPending_ = alloc("path candidates", rsBand * sizeof(dev::PathReservoir));
  diRes_ = alloc("direct light reservoirs", rsPixels * sizeof(dev::DirectReservoir));
  diPending_ = alloc("direct light candidates", rsBand * sizeof(dev::DirectReservoir));
  if (settings.resample.enabled) {
    if (own) rsEye_ = alloc("eye vertices", n * sizeof(dev::EyeVertex));
    historyOut_ = alloc("path history", n * sizeof(dev::PathHistory));
    // One chain per pass, within 1 GiB.
    const uint64_t perChain = n * sizeof(dev::PathHistory);
    const uint64_t fit = std::max<uint64_t>(1, (uint64_t(1) << 30) / perChain);
    chains_ =
        settings.resample.history > 0 ? int(std::min<uint64_t>(uint64_t(settings.spp), fit)) : 0;
    // Allocated for this device's own passes once they are known (syncChains).
    history_.resize(size_t(chains_));
    chainBytes_ = perChain;
  }
}

void PathTracer::setPasses(int begin, int end) {
  // A whole history stays whole: the caller moves the chains of passes changing device.
  const bool whole = hasHistory();
  Integrator::setPasses(begin, end);
  syncChains();
  written_ = whole ? chainedPasses() : 0;
}

void PathTracer::syncChains() {
  for (int c = 0; c < chains_; ++c) {
    cl::Buffer& b = history_[size_t(c)];
    const bool own = c >= passBegin_ && c < passEnd(settings_.spp);
    if (own && !b()) {
      b = ctx_.allocate("path history", chainBytes_);
      ctx_.zero(b, chainBytes_);  // stamp 0: no previous path
      bytes_ += chainBytes_;
    } else if (!own && b()) {
      b = cl::Buffer();
      ctx_.release("path history", chainBytes_);
      bytes_ -= chainBytes_;
    }
  }
}

size_t PathTracer::chainRowsBytes() const {
  return size_t(film_.end() - film_.first()) * sizeof(dev::PathHistory);
}

void PathTracer::readChain(int pass, char* out) {
  PR_CHECK(pass >= passBegin_ && pass < std::min(chains_, passEnd(settings_.spp)));
  CL_CHECK(ctx_.queue().enqueueReadBuffer(history_[size_t(pass)], CL_TRUE,
                                          film_.first() * sizeof(dev::PathHistory),
                                          chainRowsBytes(), out));
}

void PathTracer::writeChain(int pass, const char* records) {
  PR_CHECK(pass >= passBegin_ && pass < std::min(chains_, passEnd(settings_.spp)));
  CL_CHECK(ctx_.queue().enqueueWriteBuffer(history_[size_t(pass)], CL_TRUE,
                                           film_.first() * sizeof(dev::PathHistory),
                                           chainRowsBytes(), records));
}

std::string PathTracer::chain(int pass) {
  std::string out(chainRowsBytes(), '\0');
  readChain(pass, &out[0]);
  return out;
}

void PathTracer::setChain(int pass, const std::string& records) {
  PR_CHECK(records.size() == chainRowsBytes());
  writeChain(pass, records.data());
}

float lightTracingScale(const dev::CameraParams& camera, uint32_t slots, int spp,
                        uint32_t pathsPerPixel) {
  const double pixels = double(camera.width) * camera.height;
  return float(double(slots) * dev::camera_plane_area(&camera) /
               (double(spp) * pathsPerPixel * pixels));
}

dev::ResampleParams PathTracer::resampleParams() const {
  dev::ResampleParams p{};
  const ResampleSettings& r = settings_.resample;
  p.neighbors = cl_uint(r.neighbors);
  p.radius = r.radius;
  p.min_alpha = r.roughness * r.roughness;  // GGX alpha = roughness^2, as the materials map it
  p.min_dist2 = r.distance * r.distance;
  p.width = film_.width();
  p.height = film_.height();
  p.max_m = float(r.history);
  p.eye_count = r.enabled && settings_.pathsPerPixel > 0 ? r.misCount : 1.0f;
  return p;
}

// The instances that moved since the last frame, in moved_ for pt_resample; their count.
cl_uint PathTracer::uploadMovedInstances() {
  const std::vector<dev::MovedInstance>& moved = scene_.movedInstances();
  const uint64_t bytes = std::max<uint64_t>(moved.size(), 1) * sizeof(dev::MovedInstance);
  if (bytes > movedBytes_) {
    if (movedBytes_) ctx_.release("moved instances", movedBytes_);
    bytes_ += bytes - movedBytes_;
    moved_ = ctx_.allocate("moved instances", bytes, CL_MEM_READ_ONLY);
    ctx_.zero(moved_, bytes);
    movedBytes_ = bytes;
  }
  if (!moved.empty())
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(
        moved_, CL_FALSE, 0, moved.size() * sizeof(dev::MovedInstance), moved.data()));
  return cl_uint(moved.size());
}

void PathTracer::beginFrame(int64_t frame, const dev::CameraParams& camera,
                            const kargs::SceneArgs& sceneArgs, const cl::Buffer& radiance,
                            const cl::Buffer& eye) {
  // The film's pixels [first, n) only; buffers are indexed by pixel over the whole image.
  const cl_uint n = film_.end();
  const cl_uint rngFrame = settings_.fixedNoise ? 0 : rngFrameKey(frame);
  syncChains();
  ctx_.zero(rays_, counterBytes(dev::PR_PT_ROW));
  dev::ResampleParams rsp = resampleParams();
  if (settings_.lightTracingSlots > 0 && settings_.pathsPerPixel > 0)
    rsp.lt_scale = lightTracingScale(camera, settings_.lightTracingSlots, settings_.spp,
                                     settings_.pathsPerPixel);
  // The previous frame's reservoirs are taken where every chain was kept, the frame follows it
  // and no light changed (a light pdf in a kept path would differ).
  temporal_ = chainedPasses() > 0 && written_ >= chainedPasses() && frame == frame_ + 1 &&
              !scene_.anyLightMoved();
  const dev::CameraParams prevCamera = temporal_ ? camera_ : camera;
  frame_ = frame;
  camera_ = camera;
  written_ = 0;
  ++stamp_;
  if (settings_.resample.enabled) {
    rsp.moved_count = uploadMovedInstances();
    rsp.prev_known = temporal_ && scene_.previousKnown() ? 1u : 0u;
  }
  // Resampling needs every sample's x_1, which the path tracer alone does not keep.
  const cl::Buffer& eyeOut =
      settings_.resample.enabled && settings_.pathsPerPixel == 0 ? rsEye_ : eye;
  kargs::setScene(&extendArgs_, sceneArgs);
  extendArgs_.states = states_;
  extendArgs_.hits = hits_;
  extendArgs_.rays = rays_;
  extendArgs_.seed = settings_.seed;
  extendArgs_.frame = rngFrame;
  extendArgs_.set(extend_, kargs::kScene | kargs::kFrame);
  kargs::setScene(&shadeArgs_, sceneArgs);
  shadeArgs_.states = states_;
  shadeArgs_.hits = hits_;
  shadeArgs_.radiance = radiance;
  shadeArgs_.shadows = shadows_;
  shadeArgs_.shadow_queue = shadowQueue_;
  shadeArgs_.queue_sizes = queueSizes_;
  shadeArgs_.seed = settings_.seed;
  shadeArgs_.frame = rngFrame;
  shadeArgs_.max_depth = cl_uint(settings_.maxDepth);
  shadeArgs_.paths_per_pixel = cl_uint(settings_.pathsPerPixel);
  shadeArgs_.trace_cdf = scene_.traceCdf();
  shadeArgs_.trace_total = scene_.traceTotalPower();
  shadeArgs_.eye = eyeOut;
  shadeArgs_.rsp = rsp;
  shadeArgs_.rs_track = rsTrack_;
  shadeArgs_.rs_res = rsRes_;
  shadeArgs_.rs_pending = rsPending_;
  shadeArgs_.di_res = diRes_;
  shadeArgs_.di_pending = diPending_;
  shadeArgs_.set(shade_, kargs::kScene | kargs::kFrame);
  kargs::setScene(&shadowArgs_, sceneArgs);
  shadowArgs_.radiance = radiance;
  shadowArgs_.shadows = shadows_;
  shadowArgs_.rays = rays_;
  shadowArgs_.shadow_queue = shadowQueue_;
  shadowArgs_.seed = settings_.seed;
  shadowArgs_.frame = rngFrame;
  shadowArgs_.resample = settings_.resample.enabled ? 1u : 0u;
  shadowArgs_.rs_res = rsRes_;
  shadowArgs_.rs_pending = rsPending_;
  shadowArgs_.di_res = diRes_;
  shadowArgs_.di_pending = diPending_;
  shadowArgs_.set(shadow_, kargs::kScene | kargs::kFrame);
  if (settings_.resample.enabled) {
    kargs::setScene(&resampleArgs_, sceneArgs);
    resampleArgs_.rsp = rsp;
    resampleArgs_.eye = eyeOut;
    resampleArgs_.rs_res = rsRes_;
    resampleArgs_.di_res = diRes_;
    resampleArgs_.radiance = radiance;
    resampleArgs_.seed = settings_.seed;
    resampleArgs_.frame = rngFrame;
    resampleArgs_.first = film_.first();
    resampleArgs_.end = n;
    resampleArgs_.rays = rays_;
    resampleArgs_.prev_cam = prevCamera;
    resampleArgs_.cam = camera;
    resampleArgs_.moved = moved_;
    resampleArgs_.prev_vertices = scene_.previousVertices();
    resampleArgs_.prev_instances = scene_.previousInstances();
    resampleArgs_.stamp = stamp_;
    resampleArgs_.prev_sweeps = scene_.previousSweeps();
    resampleArgs_.prev_sweep_count = scene_.previousSweepCount();
    resampleArgs_.cam_steps = scene_.cameraSteps();
    resampleArgs_.cam_step_count = scene_.motionSteps();
    resampleArgs_.set(resample_, kargs::kScene | kargs::kFrame);
  }
  generateArgs_.seed = settings_.seed;
  generateArgs_.frame = rngFrame;
  generateArgs_.states = states_;
  generateArgs_.radiance = radiance;
  generateArgs_.eye = eyeOut;
  generateArgs_.write_eye = settings_.pathsPerPixel > 0 || settings_.resample.enabled ? 1 : 0;
  generateArgs_.resample = settings_.resample.enabled ? 1u : 0u;
  generateArgs_.rs_res = rsRes_;
  generateArgs_.di_res = diRes_;
  generateArgs_.queue = queues_[0];
  generateArgs_.queue_size = queueSizes_;
  generateArgs_.budget = film_.budget();
  generateArgs_.cam_steps = scene_.cameraSteps();
  generateArgs_.cam_step_count = scene_.cameraMotionSteps();  // 1: not blended per sample
  generateArgs_.cam =
      scene_.cameraMotionSteps() < scene_.motionSteps() ? scene_.stillCamera() : camera;
  generateArgs_.set(generate_);
}

void PathTracer::traceBand(cl_uint first, cl_uint end, cl_uint masked, StageTimer* timer) {
  static const cl_uint kZero[dev::PR_QUEUE_COUNT] = {};
  generateArgs_.first = first;
  generateArgs_.count = end;
  generateArgs_.masked = masked;
  generateArgs_.set(generate_, kargs::kPass);
  extendArgs_.base = shadeArgs_.base = shadowArgs_.base = first;
  if (masked)
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(queueSizes_, CL_FALSE, 0, sizeof kZero, kZero));
  ctx_.launch1D(generate_, first, end, "generate", timer);
  // Each bounce runs over the paths still live (a queue pt_shade compacts), and traces the shadow
  // rays it wrote; the queues' sizes come back to size the next launches, and the band ends once
  // no path is live. A masked pass starts with the pixels that take it.
  cl_uint live = end - first;
  if (masked) {
    CL_CHECK(
        ctx_.queue().enqueueReadBuffer(queueSizes_, CL_TRUE, dev::PR_QUEUE_LIVE * 4, 4, &live));
    PR_CHECK(live <= end - first);
  }
  for (int d = 0; d < settings_.maxDepth && live > 0; ++d) {
    const cl::Buffer& queue = queues_[d % 2];
    extendArgs_.queue = queue;
    extendArgs_.count = live;
    extendArgs_.set(extend_, kargs::kPass);
    ctx_.launch1D(extend_, 0, live, "extend", timer);
    CL_CHECK(ctx_.queue().enqueueWriteBuffer(queueSizes_, CL_FALSE, 0, sizeof kZero, kZero));
    shadeArgs_.queue = queue;
    shadeArgs_.count = live;
    shadeArgs_.next_queue = queues_[(d + 1) % 2];
    shadeArgs_.set(shade_, kargs::kPass);
    ctx_.launch1D(shade_, 0, live, "shade", timer);
    cl_uint sizes[dev::PR_QUEUE_COUNT] = {};
    CL_CHECK(ctx_.queue().enqueueReadBuffer(queueSizes_, CL_TRUE, 0, sizeof sizes, sizes));
    PR_CHECK(sizes[dev::PR_QUEUE_LIVE] <= live && sizes[dev::PR_QUEUE_SHADOW] <= live);
    shadowArgs_.count = sizes[dev::PR_QUEUE_SHADOW];
    shadowArgs_.set(shadow_, kargs::kPass);
    ctx_.launch1D(shadow_, 0, sizes[dev::PR_QUEUE_SHADOW], "shadow", timer);
    live = sizes[dev::PR_QUEUE_LIVE];
  }
}

void PathTracer::tracePass(int sample, cl_uint masked, StageTimer* timer) {
  const cl_uint first = film_.first(), n = film_.end();
  generateArgs_.sample = extendArgs_.sample = shadeArgs_.sample = shadowArgs_.sample =
      cl_uint(sample);
  for (cl_uint a = first; a < n; a += band_)
    traceBand(a, std::min<cl_uint>(n, a + band_), masked, timer);
  if (settings_.resample.enabled) {
    const bool chained = sample < chains_;
    resampleArgs_.sample = cl_uint(sample);
    resampleArgs_.temporal = temporal_ && chained ? 1u : 0u;
    resampleArgs_.history = chained ? history_[size_t(sample)] : historyOut_;
    resampleArgs_.history_out = historyOut_;
    resampleArgs_.pixels = film_.pixelList();
    resampleArgs_.listed = masked;
    resampleArgs_.list_count = film_.listCount();
    resampleArgs_.set(resample_, kargs::kPass);
    ctx_.launch1D(resample_, 0, masked ? film_.listCount() : n - first, "resample", timer);
    if (chained) {
      // The records just written become the chain, and the chain's old ones, all read, the next
      // pass's output (each pass writes every record of the film's rows): no copy.
      std::swap(historyOut_, history_[size_t(sample)]);
      ++written_;
    }
  }
}

std::string PathTracer::writeHistory(const std::string& key) {
  PR_CHECK(hasHistory());
  HistoryHeader h{};
  h.key = Hash128().add(key).low();
  h.frame = frame_;
  h.stamp = stamp_;
  // This device's chains alone: those of its passes (the others it never writes).
  h.chains = cl_uint(chainedPasses());
  h.first = film_.first();
  h.end = film_.end();
  h.camera = camera_;
  std::string out = beginHistoryPart(h);
  for (uint32_t c = 0; c < h.chains; ++c) readChain(passBegin_ + int(c), historyRecords(&out, c));
  sealHistoryPart(&out);
  return out;
}

bool PathTracer::checkHistory(const std::string& data, const std::string& key,
                              int64_t frame) const {
  if (chainedPasses() == 0) return false;
  HistoryLayout want;
  want.key = Hash128().add(key).low();
  want.frame = frame;
  want.chains = cl_uint(chainedPasses());
  want.first = film_.first();
  want.end = film_.end();
  HistoryScene scene;
  scene.lights = uint32_t(scene_.lights().size());
  scene.validSurface = [this](uint32_t prim, uint32_t inst) {
    return scene_.validSurface(prim, inst);
  };
  HistoryHeader h{};
  return checkHistoryPart(data, want, scene, &h);
}

void PathTracer::applyHistory(const std::string& data) {
  HistoryHeader h{};
  PR_CHECK(data.size() >= sizeof h);
  std::memcpy(&h, data.data(), sizeof h);
  syncChains();
  for (uint32_t c = 0; c < h.chains; ++c) writeChain(passBegin_ + int(c), historyRecords(data, c));
  frame_ = h.frame;
  stamp_ = h.stamp;
  camera_ = h.camera;
  written_ = chainedPasses();
}

void PathTracer::reportRays(FrameStats* stats) {
  const auto rays = readCounters<dev::PR_PT_COUNT>(ctx_, rays_, dev::PR_PT_ROW);
  if (!stats) return;
#define PR_PT_REPORT(name, key) stats->rays[key] += rays[dev::PR_PT_##name];
  PR_PT_COUNTERS(PR_PT_REPORT)
#undef PR_PT_REPORT
}

void PathTracer::renderFrame(int64_t frame, const dev::CameraParams& camera, FrameStats* stats) {
  PR_CHECK(settings_.pathsPerPixel == 0);  // PathReuse renders the frames of its eye paths
  const Clock::time_point start = Clock::now();
  StageTimer timer;
  beginFrame(frame, camera, scene_.kernelArgs(), radiance_, noEye_);
  int passes = 0, s = passBegin_;
  for (; s < passEnd(settings_.spp) && film_.passWanted(s); ++s) {
    tracePass(s, film_.beginPass(s, &timer), &timer);
    film_.accumulate(radiance_, s, &timer);
    // Wait for each pass, so that an interrupt stops a frame of many samples within one pass.
    ctx_.finish();
    if (interrupted()) return;
    ++passes;
    if (outOfTime(start)) break;
  }
  if (!film_.passWanted(s)) skipPasses(s);
  if (stats) stats->passes = passes;
  reportRays(stats);
  if (stats) {
    for (const auto& [k, v] : timer.collect()) stats->stageSeconds[k] += v;
  } else {
    timer.collect();
  }
}

}  // namespace pr
