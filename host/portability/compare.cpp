#include "portability/compare.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "util/error.h"

namespace pr {

namespace {

// Share of pixels left out of each statistic of the verdict (compare.h says why).
constexpr double kTrimFraction = 0.01;

double luminance(const float* p) {
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

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
  d.identical =
      std::memcmp(test.rgba.data(), ref.rgba.data(), test.rgba.size() * sizeof(float)) == 0;
  std::vector<double> rel, lumDiff;  // per finite pixel
  rel.reserve(pixels);
  lumDiff.reserve(pixels);
  double abs = 0.0, lum = 0.0, refLum = 0.0;
  for (size_t i = 0; i < pixels; ++i) {
    const float* t = &test.rgba[i * 4];
    const float* r = &ref.rgba[i * 4];
    bool finite = true;
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(t[c])) ++d.nonFinite, finite = false;
      if (!std::isfinite(r[c])) ++d.nonFinite, finite = false;
    }
    if (!finite) continue;  // counted above; a NaN would hide every other number
    double e = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double diff = double(t[c]) - double(r[c]);
      e += diff * diff / (double(r[c]) * r[c] + 0.01);
      abs += std::fabs(diff);
    }
    rel.push_back(e / 3.0);
    const double lt = luminance(t), lr = luminance(r);
    lum += lt;
    refLum += lr;
    lumDiff.push_back(lt - lr);
  }
  const size_t n = rel.size();
  if (n == 0) return d;
  d.mad = abs / (3.0 * n);
  d.meanLum = lum / n;
  d.refMeanLum = refLum / n;

  const size_t trim = static_cast<size_t>(kTrimFraction * double(n));
  double relSum = 0.0;
  for (double e : rel) relSum += e;
  d.relMse = relSum / n;
  // The largest terms are dropped, but the sum is still divided by n: with nothing to drop
  // the trimmed value equals the plain one.
  if (trim > 0) std::nth_element(rel.begin(), rel.begin() + (n - trim), rel.end());
  double kept = 0.0;
  for (size_t i = 0; i + trim < n; ++i) kept += rel[i];
  d.relMseTrimmed = trim > 0 ? kept / n : d.relMse;

  // Trimmed mean of the luminance difference, `trim` pixels off each end; its standard error
  // from the winsorized variance (the trimmed values replaced by the nearest kept ones).
  std::sort(lumDiff.begin(), lumDiff.end());
  const size_t t2 = std::min(trim, (n - 1) / 2);
  double mean = 0.0;
  for (size_t i = t2; i < n - t2; ++i) mean += lumDiff[i];
  mean /= double(n - 2 * t2);
  double wMean = 0.0, wVar = 0.0;
  auto winsorized = [&](size_t i) { return lumDiff[std::min(std::max(i, t2), n - 1 - t2)]; };
  for (size_t i = 0; i < n; ++i) wMean += winsorized(i);
  wMean /= double(n);
  for (size_t i = 0; i < n; ++i) wVar += (winsorized(i) - wMean) * (winsorized(i) - wMean);
  wVar /= double(n);
  const double kept2 = double(n - 2 * t2) / double(n);
  d.lumDiff = mean;
  d.lumDiffStdErr = std::sqrt(wVar) / (kept2 * std::sqrt(double(n)));
  return d;
}

std::vector<NoiseFloor> measureNoiseFloors(const std::vector<Image>& ref,
                                           const std::vector<std::vector<Image>>& others) {
  if (others.empty()) throw RuntimeError("noise floor: no render with another seed");
  std::vector<NoiseFloor> floors(ref.size());
  double sumSq = 0.0;
  size_t count = 0;
  for (size_t f = 0; f < ref.size(); ++f) {
    NoiseFloor& fl = floors[f];
    for (const auto& set : others) {
      const ImageDiff d = compareImages(set.at(f), ref[f]);
      fl.relMse += d.relMse / double(others.size());
      fl.relMseTrimmed += d.relMseTrimmed / double(others.size());
      fl.lumStdErrPixels += d.lumDiffStdErr / double(others.size());
      fl.nonFinite += d.nonFinite;
      sumSq += d.lumDiff * d.lumDiff;
      ++count;
    }
  }
  const double seeds = count > 0 ? std::sqrt(sumSq / double(count)) : 0.0;
  for (auto& fl : floors) {
    fl.lumStdErrSeeds = seeds;
    fl.lumStdErr = std::max(fl.lumStdErrPixels, seeds);
  }
  return floors;
}

Verdict judge(const ImageDiff& diff, const NoiseFloor& floor, const Tolerance& tol,
              uint64_t droppedSamples, uint64_t refDroppedSamples) {
  Verdict v;
  const double inf = std::numeric_limits<double>::infinity();
  v.relMseRatio = floor.relMseTrimmed > 0.0 ? diff.relMseTrimmed / floor.relMseTrimmed
                                            : (diff.relMseTrimmed > 0.0 ? inf : 0.0);
  const double dLum = std::fabs(diff.lumDiff);
  v.lumZ = floor.lumStdErr > 0.0 ? dLum / floor.lumStdErr : (dLum > 0.0 ? inf : 0.0);
  auto fail = [&](std::string why) {
    v.agree = false;
    v.reasons.push_back(std::move(why));
  };
  if (diff.nonFinite > 0) fail(std::to_string(diff.nonFinite) + " non-finite pixel values");
  if (diff.identical) return v;  // nothing else can be wrong that the reference does not share
  if (droppedSamples > 0 && refDroppedSamples == 0)
    fail(std::to_string(droppedSamples) + " non-finite samples dropped (none on the reference)");
  if (diff.relMseTrimmed > tol.relMseFactor * floor.relMseTrimmed + tol.relMseSlack)
    fail("relMSE above the noise floor");
  // With a zero floor, a relative 1e-5 stands for float round-off in the sums.
  if (dLum > tol.lumSigmas * floor.lumStdErr && dLum > 1e-5 * std::fabs(diff.refMeanLum))
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
