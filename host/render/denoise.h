// Intel Open Image Denoise 2 (--denoise), loaded at run time so that the renderer builds and
// runs without it: from PATHREUSE_OIDN (the library file), else the user's cache where
// tools/setup/oidn.sh installs it, else the system's library path.
#pragma once

#include <memory>
#include <string>

namespace pr {

class Denoiser {
 public:
  // Loads the library; throws InputError, one line saying where it looked and how to install
  // it, where it is not found or lacks a function.
  Denoiser();
  ~Denoiser();
  Denoiser(const Denoiser&) = delete;
  Denoiser& operator=(const Denoiser&) = delete;

  // Denoises `color` (w x h RGB floats, HDR) in place with its auxiliary images: albedo and
  // normal are first denoised themselves, in place, as OIDN recommends for noisy ones, and the
  // colour's filter then takes them as clean. The first call creates OIDN's device (its
  // default: a GPU where OIDN supports one, else the CPU). Throws RuntimeError on OIDN's errors.
  void denoise(int w, int h, float* color, const float* albedo, const float* normal);
  // OIDN's device as it names its type ("CPU", "CUDA", ...), once denoise has run.
  std::string deviceType() const;

 private:
  struct Api;
  std::unique_ptr<Api> api_;
};

}  // namespace pr
