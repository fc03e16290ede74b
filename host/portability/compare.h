// Comparing one device's frame with the reference device's frame when the two may legitimately
// differ by Monte Carlo noise: float round-off can send a path another way on another device,
// after which that pixel is simply another random estimate of the same integral.
//
// The tolerance is therefore statistical and measured, not guessed. Next to the suite the
// reference device renders every frame again with two other seeds; these independent
// estimates give each frame's noise floor. A device whose paths diverge by
// round-off is at worst another seed, so its error against the reference stays at or below the
// floor; a real fault (a wrong BSDF, a missing light, broken invalidation, a NaN) adds a
// systematic difference on top of the noise.
//
// Both statistics of the verdict leave out the 1% most extreme pixels. Unclamped connections
// make fireflies, and a firefly or two decides plain relMSE: between independent renders of the
// demo scenes at 64x48, 8 spp, its ratio to the floor ranged from 0.03 to 28, while without the
// worst 1% of pixels it stayed within 0.8 to 1.3 (96 frames), and the trimmed mean luminance
// difference within 3.8 standard errors. Measured sensitivity at those settings: a light 10%
// dimmer gives 6 to 9 standard errors, the red wall turned blue a relMSE ratio of 2.2 to 3.2;
// a grey instead of a yellow sphere (3% of the pixels) stays within the noise and is missed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/image.h"

namespace pr {

// Per-pixel error metrics of `test` against `ref` (same size; RGB only, alpha ignored).
struct ImageDiff {
  double relMse = 0.0;  // mean over pixels and channels of (I - R)^2 / (R^2 + 0.01)
  double relMseTrimmed =
      0.0;           // the same sum without the pixels with the 1% largest terms, over all pixels
  double mad = 0.0;  // mean absolute difference over pixels and channels
  double meanLum = 0.0;     // mean Rec.709 luminance of `test`
  double refMeanLum = 0.0;  // same of `ref`
  double lumDiff = 0.0;     // trimmed mean (1% off each end) of the per-pixel luminance difference
  double lumDiffStdErr =
      0.0;  // its standard error from the winsorized spread, pixels taken as independent
  uint64_t nonFinite = 0;  // non-finite values in either image
  bool identical = false;  // bit for bit
};

// Throws RuntimeError when the sizes differ (an internal error: both come from one session setup).
ImageDiff compareImages(const Image& test, const Image& ref);

// The noise of one frame, measured between independent renders at the same settings.
struct NoiseFloor {
  double relMse = 0.0;         // relMSE of another seed's render against the reference's
  double relMseTrimmed = 0.0;  // the same without the worst 1% of pixels
  // Standard error of the trimmed mean luminance difference between independent renders: the
  // larger of the estimate from the pixels' spread (exact when pixels are independent, as in
  // pathtrace) and the one from the spread of the differences themselves across seeds and
  // frames (which also holds when pixels share light paths, as in reuse; there the pixel
  // estimate alone was too small by up to 2x).
  double lumStdErr = 0.0;
  double lumStdErrPixels = 0.0;
  double lumStdErrSeeds = 0.0;
  uint64_t nonFinite = 0;  // non-finite values in the renders
};

// Per frame, from the reference renders `ref[f]` and renders of the same frames with other
// seeds `others[k][f]` (at least one set). The seed spread is pooled over all frames and seeds.
std::vector<NoiseFloor> measureNoiseFloors(const std::vector<Image>& ref,
                                           const std::vector<std::vector<Image>>& others);

struct Tolerance {
  // A device disagrees when its trimmed relMSE exceeds relMseFactor x the floor's. At most 1x is
  // expected (diverged pixels are independent estimates, the rest identical); 2x leaves room
  // for the spread of the estimate itself (measured: 0.8x to 1.3x).
  double relMseFactor = 2.0;
  // ... or when its trimmed mean luminance is more than this many floor standard errors away
  // (measured: at most 3.8 between independent renders).
  double lumSigmas = 5.0;
  // Absolute slack for a frame with no noise at all (a floor of zero): float round-off only.
  double relMseSlack = 1e-6;
};

struct Verdict {
  bool agree = true;
  double relMseRatio =
      0.0;            // trimmed relMSE / the floor's (0 when both are 0, inf for a zero floor)
  double lumZ = 0.0;  // |trimmed mean luminance difference| in floor standard errors
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
