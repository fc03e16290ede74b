// Auxiliary images (--aov): albedo, normal, depth, motion, object and material ids, written as
// extra channels of each frame's EXR (docs/design.md section 5, "Auxiliary images"). Computed
// on one device for the whole image, whatever the mode and the split between devices, by
// kernels/aov.cl.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cl/context.h"
#include "io/image.h"
#include "render/gpu_scene.h"
#include "scene/scene.h"

namespace pr {

// The images --aov can ask for, as bits.
enum AovBits : uint32_t {
  kAovAlbedo = 1u,
  kAovNormal = 2u,
  kAovDepth = 4u,
  kAovMotion = 8u,
  kAovObject = 16u,
  kAovMaterial = 32u,
};

// --aov's comma-separated list (albedo, normal, depth, motion, object, material; "all") as bits.
// Throws InputError naming the option and the name it does not know.
uint32_t parseAovs(const std::string& list);

// What the camera samples of a frame were keyed by, so that each pass's auxiliary ray goes
// through the point of the pixel its colour sample did.
struct AovSampling {
  uint32_t seed = 1;
  bool jitterFromFrame0 = false;  // --resample or --fixed-noise: frame 0's points every frame
  int spp = 4;
  int maxDepth = 8;
};

class AovRenderer {
 public:
  // `scene` and `gpu` must outlive this.
  AovRenderer(Context& ctx, const Scene& scene, GpuScene& gpu, uint32_t aovs,
              const AovSampling& sampling);
  // Adds the channels of frame f (at time f / fps, the GpuScene set to it) to `image`.
  // Returns the kernel's seconds.
  double render(int frame, double fps, int camera, Image* image);

 private:
  // The dynamic meshes' vertices at time t, in object space, as the device's vertex array
  // orders them after the SSG's (deformed meshes at their shapes then).
  void uploadPrevious(double t);

  Context& ctx_;
  const Scene& scene_;
  GpuScene& gpu_;
  uint32_t aovs_;
  AovSampling sampling_;
  cl::Kernel kernel_;
  cl::Buffer out_, prevInst_, prevPos_, triObject_, instObject_;
  bool anyDeforms_ = false;
  bool restUploaded_ = false;
  uint32_t outPixels_ = 0;
};

}  // namespace pr
