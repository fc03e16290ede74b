#include "portability/compare.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "util/error.h"

namespace pr {

namespace {

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

void checkSizes(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.rgba.size() != b.rgba.size() ||
      a.rgba.size() != static_cast<size_t>(a.width) * a.height * 4)
    throw RuntimeError("image comparison: sizes differ (" + std::to_string(a.width) + "x" +
                       std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                       std::to_string(b.height) + ")");
}

}  // namespace

ImageDiff compareImages(const Image& test, const Image& ref) {
  checkSizes(test, ref);
  ImageDiff d;
  const size_t pixels = static_cast<size_t>(test.width) * test.height;
  d.identical = std::memcmp(test.rgba.data(), ref.rgba.data(), test.rgba.size() * sizeof(float)) == 0;
  double rel = 0.0, abs = 0.0, lum = 0.0, refLum = 0.0, lumSq = 0.0;
  for (size_t i = 0; i < pixels; ++i) {
    const float* t = &test.rgba[i * 4];
    const float* r = &ref.rgba[i * 4];
    bool finite = true;
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(t[c])) ++d.nonFinite, finite = false;
      if (!std::isfinite(r[c])) ++d.nonFinite, finite = false;
    }
    if (!finite) continue;  // counted above; a NaN would hide every other number
    for (int c = 0; c < 3; ++c) {
      const double e = double(t[c]) - double(r[c]);
      rel += e * e / (double(r[c]) * r[c] + 0.01);
      abs += std::fabs(e);
    }
    const double lt = luminance(t), lr = luminance(r);
    lum += lt;
    refLum += lr;
    lumSq += (lt - lr) * (lt - lr);
  }
  if (pixels > 0) {
    d.relMse = rel / (3.0 * pixels);
    d.mad = abs / (3.0 * pixels);
    d.meanLum = lum / pixels;
    d.refMeanLum = refLum / pixels;
    d.lumRmsDiff = std::sqrt(lumSq / pixels);
  }
  return d;
}

NoiseFloor noiseFloor(const Image& otherSeed, const Image& ref) {
  const ImageDiff d = compareImages(otherSeed, ref);
  NoiseFloor f;
  f.relMse = d.relMse;
  // Two independent renders: the difference of their means has the per-pixel spread of the
  // difference over sqrt(pixels).
  const size_t pixels = static_cast<size_t>(ref.width) * ref.height;
  f.lumStdErr = pixels > 0 ? d.lumRmsDiff / std::sqrt(double(pixels)) : 0.0;
  f.nonFinite = d.nonFinite;
  return f;
}

Verdict judge(const ImageDiff& diff, const NoiseFloor& floor, const Tolerance& tol,
              uint64_t droppedSamples, uint64_t refDroppedSamples) {
  Verdict v;
  const double inf = std::numeric_limits<double>::infinity();
  v.relMseRatio = floor.relMse > 0.0 ? diff.relMse / floor.relMse : (diff.relMse > 0.0 ? inf : 0.0);
  const double dLum = std::fabs(diff.meanLum - diff.refMeanLum);
  v.lumZ = floor.lumStdErr > 0.0 ? dLum / floor.lumStdErr : (dLum > 0.0 ? inf : 0.0);
  if (diff.identical) return v;  // nothing can be wrong that the reference does not share
  auto fail = [&](std::string why) {
    v.agree = false;
    v.reasons.push_back(std::move(why));
  };
  if (diff.nonFinite > 0) fail(std::to_string(diff.nonFinite) + " non-finite pixel values");
  if (droppedSamples > 0 && refDroppedSamples == 0)
    fail(std::to_string(droppedSamples) + " non-finite samples dropped (none on the reference)");
  if (diff.relMse > tol.relMseFactor * floor.relMse + tol.relMseSlack) fail("relMSE above the noise floor");
  // The luminance test is skipped only when both means are exactly equal (a zero floor).
  if (dLum > tol.lumSigmas * floor.lumStdErr && dLum > 1e-7 * std::fabs(diff.refMeanLum))
    fail("mean luminance off by more than the noise");
  return v;
}

Image differenceImage(const Image& test, const Image& ref, double* scale) {
  checkSizes(test, ref);
  Image out(test.width, test.height);
  std::vector<float> nonZero;
  for (size_t i = 0; i < out.rgba.size(); i += 4) {
    for (int c = 0; c < 3; ++c) {
      float e = std::fabs(test.rgba[i + c] - ref.rgba[i + c]);
      if (!std::isfinite(e)) e = std::numeric_limits<float>::infinity();  // shown as full white
      out.rgba[i + c] = e;
      if (e > 0.0f) nonZero.push_back(e);
    }
    out.rgba[i + 3] = 1.0f;
  }
  double s = 1.0;
  if (!nonZero.empty()) {
    const size_t k = std::min(nonZero.size() - 1, size_t(0.99 * double(nonZero.size())));
    std::nth_element(nonZero.begin(), nonZero.begin() + k, nonZero.end());
    const float p99 = nonZero[k];
    if (std::isfinite(p99) && p99 > 0.0f) s = 1.0 / p99;
  }
  for (size_t i = 0; i < out.rgba.size(); i += 4)
    for (int c = 0; c < 3; ++c) out.rgba[i + c] = std::min(1.0f, float(out.rgba[i + c] * s));
  if (scale) *scale = s;
  return out;
}

}  // namespace pr
