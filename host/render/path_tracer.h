// The baseline: a unidirectional wavefront path tracer (--mode pathtrace), the paper's
// "traditional path tracing". Stages: generate, then per bounce extend, shade, shadow over queues
// of the live paths (as pbrt-v4's wavefront); then accumulate into the film. Next-event estimation
// with MIS, Russian roulette.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "cl/context.h"
#include "cl/kernel_binding.h"
#include "render/film.h"
#include "render/gpu_scene.h"
#include "render/integrator.h"
#include "render/options.h"

namespace pr {

struct PathTracerSettings {
  int spp = 4;
  int maxDepth = 8;
  uint32_t seed = 1;
  bool fixedNoise = false;  // RNG keyed by frame 0 on every frame
  // --eye-paths: C (--paths-per-pixel), the light paths per camera sample that path reuse joins
  // to each first eye vertex; the ends of eye paths on lights are weighted against those
  // connections (kernels/shared/eye_paths.h). 0: the path tracer alone.
  uint32_t pathsPerPixel = 0;
  // --light-tracing: the N_L stored light paths that strategy T joins to the camera, against
  // which the eye paths are weighted too (0: off).
  uint32_t lightTracingSlots = 0;
  // --resample (kernels/shared/resample.h), its distance resolved (> 0, scene units).
  ResampleSettings resample;
  // A pass traces the film's pixels in bands of at most this many: each path's own state (about
  // 570 bytes with resampling) is kept for a band, not for the whole image.
  uint32_t wavefrontPixels = kWavefrontPixels;
};

// Strategy T's scale N_L A / (spp C W H) (kernels/shared/eye_paths.h): light paths, samples per
// pixel, light paths per camera sample and the camera's image (plane area A, W x H pixels).
float lightTracingScale(const dev::CameraParams& camera, uint32_t slots, int spp,
                        uint32_t pathsPerPixel);

class PathTracer : public Integrator, public FrameHistory {
 public:
  PathTracer(Context& ctx, GpuScene& scene, Film& film, const PathTracerSettings& settings);
  void renderFrame(int64_t frame, const dev::CameraParams& camera, FrameStats* stats) override;
  uint64_t deviceBytes() const override { return bytes_; }

  // One frame's kernel arguments, with the samples' radiance written to `radiance` (one float4
  // per pixel) and, with pathsPerPixel > 0, each sample's first non-delta vertex to `eye` (one
  // EyeVertex per pixel); then one pass per sample index, which leaves both for the caller.
  // sceneArgs: the scene's arguments for this frame (GpuScene::kernelArgs).
  void beginFrame(int64_t frame, const dev::CameraParams& camera, const kargs::SceneArgs& sceneArgs,
                  const cl::Buffer& radiance, const cl::Buffer& eye);
  // masked: Film::beginPass's answer for the pass.
  void tracePass(int sample, cl_uint masked, StageTimer* timer);
  // Passes [from, end) of this device that no pixel takes this frame (--noise-threshold): their
  // chains keep an earlier frame's records, whose stamps the next frame does not take, so the
  // history stays whole.
  void skipPasses(int from) {
    written_ += std::max(0, std::min(chains_, passEnd(settings_.spp)) - std::max(from, passBegin_));
  }
  // The rays the passes since beginFrame traced, into stats.
  void reportRays(FrameStats* stats);

  // --resample's history between frames (docs/design.md section 5), so that a resumed run goes
  // on as the uninterrupted one would: a header, the chains' records of the film's rows, a
  // checksum. A history of another key, size or frame is not read.
  FrameHistory* history() override { return this; }
  bool hasHistory() const override { return chainedPasses() > 0 && written_ >= chainedPasses(); }
  std::string writeHistory(const std::string& key) override;
  bool checkHistory(const std::string& data, const std::string& key, int64_t frame) const override;
  void applyHistory(const std::string& data) override;

  // Several devices: each holds the chains of its own passes alone, and a pass moving to another
  // device takes its chain along.
  void setPasses(int begin, int end) override;
  int chains() const override { return chains_; }
  std::string chain(int pass) override;
  void setChain(int pass, const std::string& records) override;

 private:
  // The instances that moved since the last frame, in moved_ for pt_resample; their count.
  cl_uint uploadMovedInstances();
  dev::ResampleParams resampleParams() const;
  // The paths of the film's pixels [first, end) (one band: at most band_) through every bounce.
  void traceBand(cl_uint first, cl_uint end, cl_uint masked, StageTimer* timer);
  // Allocates the chains of this device's passes (zeroed: no history) and frees the others'.
  void syncChains();
  // One chain's records of the film's rows (chainRowsBytes of them), read or written; `pass` is
  // this device's and chained.
  size_t chainRowsBytes() const;
  void readChain(int pass, char* out);
  void writeChain(int pass, const char* records);
  // This device's passes that keep a chain: each wrote its chain when the frame is whole.
  int chainedPasses() const {
    return std::max(0, std::min(chains_, passEnd(settings_.spp)) - passBegin_);
  }

  Context& ctx_;
  GpuScene& scene_;
  Film& film_;
  PathTracerSettings settings_;
  cl::Kernel generate_, extend_, shade_, shadow_, resample_;
  // Kept between beginFrame and the passes, which change the sample index and the queues.
  kargs::PtGenerateArgs generateArgs_;
  kargs::PtExtendArgs extendArgs_;
  kargs::PtShadeArgs shadeArgs_;
  kargs::PtShadowArgs shadowArgs_;
  kargs::PtResampleArgs resampleArgs_;
  uint32_t band_ = 0;  // the pixels a band of a pass holds (its paths' own buffers' length)
  cl::Buffer states_, hits_, radiance_, shadows_, rays_;
  cl::Buffer queues_[2];    // the live paths' indices, at this bounce and the next
  cl::Buffer shadowQueue_;  // the paths with a shadow ray at this bounce
  cl::Buffer queueSizes_;   // PR_QUEUE_* (kernels/shared/path_state.h)
  cl::Buffer noEye_;        // the eye-vertex argument when nothing is written there
  // --resample: each path's candidates as it goes, its sample's reservoir, next-event
  // estimation's candidate until pt_shadow, and x_1 (when the caller gives no eye buffer).
  cl::Buffer rsTrack_, rsRes_, rsPending_, rsEye_, diRes_, diPending_;
  // Temporal reuse: pass s < chains_ keeps its final reservoirs in history_[s] for pass s of the
  // next frame (pt_resample writes historyOut_, swapped with it): chains_ = spp as far as 1 GiB
  // allows; later passes resample within the frame alone. Only this device's passes' chains
  // are allocated; the others' buffers are empty.
  std::vector<cl::Buffer> history_;
  cl::Buffer historyOut_, moved_;
  uint64_t movedBytes_ = 0;
  int chains_ = 0;
  uint64_t chainBytes_ = 0;     // one chain: a record per pixel of the image
  int written_ = 0;             // passes of the frame since beginFrame whose chain is written
  int64_t frame_ = -2;          // the frame of the last beginFrame
  dev::CameraParams camera_{};  // and its camera
  bool temporal_ = false;       // this frame resamples with the previous frame's history
  // Counts beginFrame calls: the history's stamp (zeroed records' 0 never precedes one).
  cl_uint stamp_ = 1;
  uint64_t bytes_ = 0;
};

}  // namespace pr
