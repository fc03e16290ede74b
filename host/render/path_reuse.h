// The paper's method (--mode reuse), made exact (docs/design.md sections 4 and 5): light sub-paths
// live in a path-record arena across frames; each frame `invalidate` finds the ones the moving
// objects disturb, `light_trace` traces those again, and per sample `eye_hit` finds the first
// non-delta surface and `connect` joins it to the stored light vertices. --mode retrace runs
// the same kernels with every slot traced again each frame.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "cl/context.h"
#include "cl/kernel_binding.h"
#include "render/film.h"
#include "render/gpu_scene.h"
#include "render/integrator.h"
#include "render/path_tracer.h"
#include "shared/arena.h"
#include "shared/reuse.h"

namespace pr {

// N_L where --light-paths is not given: one light path per pixel, at most 2^21 (1080p's 2,073,600
// pixels keep one each; 4K shares one among four pixels). On the Cornell box a quarter of a path
// per pixel costs 10% more relMSE at equal spp, a sixteenth the same, on the atrium nothing; at 4K
// the whole arena would take 4.2 GiB of device memory (docs/experiments/device-memory.md).
constexpr uint32_t kMaxDefaultLightPaths = uint32_t(1) << 21;
inline uint32_t defaultLightPaths(uint64_t pixels) {
  return uint32_t(std::min<uint64_t>(pixels, kMaxDefaultLightPaths));
}

// ConnectionSettings' defaults as PathReuse takes them: every candidate traced, no strategy T.
inline ConnectionSettings resolvedConnectionDefaults() {
  ConnectionSettings c;
  c.resample = 0;
  c.lightTracing = false;
  return c;
}

struct PathReuseSettings {
  int spp = 4;
  int maxDepth = 8;
  uint32_t seed = 1;
  // The connections, resolved: `resample` >= 0 (0: every candidate), `lightTracing` given.
  ConnectionSettings connect = resolvedConnectionDefaults();
  // Device memory for connect's terms (eye paths): each launch of connect and connect_shadow
  // takes as many pixel samples as fit.
  uint64_t connectRecordBytes = uint64_t(128) << 20;
  uint32_t wavefrontPixels = kWavefrontPixels;  // the eye paths' bands (PathTracerSettings)
  bool retraceAll = false;                      // --mode retrace
  bool fixedNoise = false;                      // camera samples keyed by frame 0 on every frame
  // --resample: the eye paths resampled across pixels and frames (kernels/shared/resample.h),
  // with their share against the connections; its distance resolved (> 0, scene units).
  ResampleSettings resamplePaths;
};

class PathReuse : public Integrator {
 public:
  PathReuse(Context& ctx, GpuScene& scene, Film& film, const PathReuseSettings& settings);
  void renderFrame(int64_t frame, const dev::CameraParams& camera, FrameStats* stats) override;
  uint64_t deviceBytes() const override { return bytes_; }
  void setPasses(int begin, int end) override {
    Integrator::setPasses(begin, end);
    if (eyePaths_) eyePaths_->setPasses(begin, end);
  }

  // connect's terms per pixel sample, and the pixel samples of one launch (eye paths).
  uint32_t connectRecordCap() const { return recordCap_; }
  uint32_t connectLaunchPixels() const { return recordPixels_; }
  uint32_t slots() const { return slots_; }
  uint32_t stride() const { return stride_; }
  uint64_t arenaBytes() const {
    const uint64_t vertex =
        sizeof(dev::LightVertex) + (settings_.connect.eyePaths ? sizeof(dev::EyePathRatio) : 0);
    return uint64_t(slots_) * (sizeof(dev::PathHeader) + stride_ * vertex);
  }
  // The eye paths' --resample history is the run's (none with --no-eye-paths).
  FrameHistory* history() override { return eyePaths_.get(); }
  // The arena's slots, vertices per slot and size.
  std::string describe() const override;
  // The arena as it stands (for tests and diagnostics).
  void readArena(std::vector<dev::PathHeader>* headers, std::vector<dev::LightVertex>* vertices);

 private:
  // The slot offset of the light paths each pixel sample connects to, this frame.
  cl_uint historySlotOffset(const dev::ReuseParams& rp) const;
  dev::ReuseParams frameParams(int64_t frame) const;
  // Strategy T: the arena's vertices joined to the camera, into the film.
  void splatToCamera(const dev::CameraParams& camera, const dev::ReuseParams& rp,
                     const kargs::SceneArgs& sceneArgs, StageTimer* timer);
  // The frame's sample passes: first hits (or the eye paths), connections, the film; no pass
  // after the one during which the time limit (from `start`) ran out. Returns the passes
  // rendered, -1 when interrupted.
  int tracePasses(int64_t frame, const dev::CameraParams& camera, const dev::ReuseParams& rp,
                  const kargs::SceneArgs& sceneArgs, cl_uint frameStamp, Clock::time_point start,
                  StageTimer* timer);
  // Reads the counters and adds them and the stage times to stats.
  void report(StageTimer* timer, cl_uint toTrace, FrameStats* stats);

  Context& ctx_;
  GpuScene& scene_;
  Film& film_;
  PathReuseSettings settings_;
  uint32_t slots_ = 0, stride_ = 0;
  bool lightTracing_ = false;  // strategy T: camera_splat
  bool first_ = true;
  uint32_t frames_ = 0;  // frames rendered with a connection history: its clock
  cl::Kernel invalidate_, lightTrace_, eyeHit_, connect_, connectShadow_, cameraSplat_;
  cl::Buffer splat_;  // strategy T's fixed-point sums per pixel (kernels/shared/splat.h)
  cl::Buffer headers_, vertices_, ratios_, list_, allSlots_, eye_, radiance_, counters_;
  cl::Buffer changed_, history_;  // the connection history's slot stamps and pixel reservoirs
  // connect's terms for connect_shadow (--eye-paths): recordCap_ per pixel sample, for
  // recordPixels_ samples a launch (without eye paths, one unread element).
  cl::Buffer records_, recordCounts_;
  uint32_t recordCap_ = 0, recordPixels_ = 1;
  std::unique_ptr<PathTracer> eyePaths_;  // --eye-paths: the eye paths of every sample
  uint64_t bytes_ = 0;
};

}  // namespace pr
