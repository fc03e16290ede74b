// The baseline: a unidirectional wavefront path tracer (--mode pathtrace), the paper's
// "traditional path tracing". Stages: generate, then per bounce extend, shade, shadow; then
// accumulate into the film. Next-event estimation with MIS, Russian roulette.
#pragma once

#include "cl/context.h"
#include "render/film.h"
#include "render/gpu_scene.h"
#include "render/integrator.h"

namespace pr {

struct PathTracerSettings {
  int spp = 4;
  int maxDepth = 8;
  uint32_t seed = 1;
  bool fixedNoise = false;  // RNG keyed by frame 0 on every frame
};

class PathTracer : public Integrator {
 public:
  PathTracer(Context& ctx, GpuScene& scene, Film& film, const PathTracerSettings& settings);
  void renderFrame(int frame, const dev::CameraParams& camera, FrameStats* stats) override;
  uint64_t deviceBytes() const override { return bytes_; }

 private:
  Context& ctx_;
  GpuScene& scene_;
  Film& film_;
  PathTracerSettings settings_;
  cl::Kernel generate_, extend_, shade_, shadow_;
  cl::Buffer states_, hits_, radiance_, shadows_, rays_;
  uint64_t bytes_ = 0;
};

}  // namespace pr
