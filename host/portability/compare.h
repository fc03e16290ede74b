// Comparing one device's frame with the reference device's frame when the two may legitimately
// differ by Monte Carlo noise: float round-off can send a path another way on another device,
// after which that pixel is simply another random estimate of the same integral.
//
// The tolerance is therefore statistical and measured, not guessed. Next to the suite the
// reference device renders every frame a second time with another seed; that pair of
// independent estimates gives the noise floor of each frame:
//   - floor relMSE: relMSE between the two seeds' images;
//   - floor standard error of the mean luminance: RMS of their per-pixel luminance difference
//     over sqrt(pixels).
// A device whose paths diverge by round-off is at worst another seed, so its relMSE against the
// reference stays at or below the floor and its mean luminance within a few standard errors;
// a real fault (a wrong BSDF, a missing light, broken invalidation, a NaN) adds a systematic
// difference on top of the noise and exceeds one of them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/image.h"

namespace pr {

// Per-pixel error metrics of `test` against `ref` (same size; RGB only, alpha ignored).
struct ImageDiff {
  double relMse = 0.0;       // mean over pixels and channels of (I - R)^2 / (R^2 + 0.01)
  double mad = 0.0;          // mean absolute difference over pixels and channels
  double meanLum = 0.0;      // mean Rec.709 luminance of `test`
  double refMeanLum = 0.0;   // same of `ref`
  double lumRmsDiff = 0.0;   // RMS over pixels of the luminance difference
  uint64_t nonFinite = 0;    // non-finite values in either image
  bool identical = false;    // bit for bit
};

// Throws RuntimeError when the sizes differ (an internal error: both come from one session setup).
ImageDiff compareImages(const Image& test, const Image& ref);

// The noise of one frame, measured between two independent renders at the same settings.
struct NoiseFloor {
  double relMse = 0.0;    // relMSE between the two renders
  double lumStdErr = 0.0; // standard error of the difference of their mean luminances
  uint64_t nonFinite = 0; // non-finite values in the second render
};

NoiseFloor noiseFloor(const Image& otherSeed, const Image& ref);

struct Tolerance {
  // A device disagrees when its relMSE exceeds relMseFactor x the floor relMSE. At most 1x is
  // expected (diverged pixels are independent estimates, the rest are identical); the margin
  // covers the estimator's own spread, which is large for relMSE (fireflies).
  double relMseFactor = 3.0;
  // ... or when its mean luminance is more than this many floor standard errors away.
  double lumSigmas = 5.0;
  // Absolute slack for a frame with no noise at all (a floor of zero).
  double relMseSlack = 1e-6;
};

struct Verdict {
  bool agree = true;
  double relMseRatio = 0.0;  // relMSE / floor relMSE (0 when both are 0, inf for a zero floor)
  double lumZ = 0.0;         // mean luminance difference in floor standard errors
  std::vector<std::string> reasons;  // why it disagrees; empty when it agrees
};

// `droppedSamples` / `refDroppedSamples`: non-finite samples that the film dropped on the device
// and on the reference. A device that drops any where the reference dropped none disagrees.
Verdict judge(const ImageDiff& diff, const NoiseFloor& floor, const Tolerance& tol,
              uint64_t droppedSamples = 0, uint64_t refDroppedSamples = 0);

// |test - ref| per channel, scaled so that the 99th percentile of the non-zero differences maps
// to 1 (an all-zero image stays black); `scale` receives the factor used.
Image differenceImage(const Image& test, const Image& ref, double* scale = nullptr);

}  // namespace pr
