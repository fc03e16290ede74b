// Auxiliary images (--aov): albedo, normal, depth, motion, object and material ids, written as
// extra channels of each frame's EXR (docs/design.md section 5, "Auxiliary images"). Computed
// on one device for the whole image, whatever the mode and the split between devices, by
// kernels/aov.cl.
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <string>
#include <vector>

#include "cl/context.h"
#include "render/denoise.h"
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
  kAovSamples = 64u,  // each pixel's sample count, from the film (not kernels/aov.cl)
};

// --aov's comma-separated list (albedo, normal, depth, motion, object, material, samples; "all")
// as bits.
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
  // `scene` and `gpu` must outlive this. With `denoise`, loads Open Image Denoise (throws
  // InputError where it is missing) and computes albedo and normal for it, written only where
  // `aovs` asks for them.
  AovRenderer(Context& ctx, const Scene& scene, GpuScene& gpu, uint32_t aovs,
              const AovSampling& sampling, bool denoise);
  // Adds the channels of frame f (at time f / fps, the GpuScene set to it) to `image`; with
  // denoising, the image's colour becomes the denoised one and the noisy one the channels
  // noisy.R/G/B. Returns the seconds of the auxiliary images and of the denoising.
  std::pair<double, double> render(int64_t frame, double fps, int camera, Image* image);
  // OIDN's device type once a frame was denoised ("" before, or without --denoise).
  std::string denoiseDevice() const { return denoiser_ ? denoiser_->deviceType() : ""; }

 private:
  // The kernel and the scene's ids and previous-frame buffers on the device.
  void setUp();
  // The dynamic meshes' vertices at time t, in object space, as the device's vertex array
  // orders them after the SSG's (deformed meshes at their shapes then).
  void uploadPrevious(double t);
  // The colour denoised with the pixels' albedo and normal (v: the kernel's output).
  void denoise(const std::vector<float>& v, Image* image);

  Context& ctx_;
  const Scene& scene_;
  GpuScene& gpu_;
  uint32_t aovs_;
  std::unique_ptr<Denoiser> denoiser_;
  AovSampling sampling_;
  cl::Kernel kernel_;
  cl::Buffer out_, prevInst_, prevPos_, triObject_, instObject_;
  bool anyDeforms_ = false;
  bool restUploaded_ = false;
  uint32_t outPixels_ = 0;
};

}  // namespace pr
