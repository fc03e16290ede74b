#include "scene/environment_map.h"

#include <algorithm>
#include <cmath>

#include "io/image.h"
#include "scene/image_decode.h"
#include "util/error.h"
#include "util/input_file.h"

namespace pr {

namespace {

double luminanceOf(const float* c) {
  return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

bool endsWith(const std::string& s, const std::string& tail) {
  if (s.size() < tail.size()) return false;
  return std::equal(tail.rbegin(), tail.rend(), s.rbegin(),
                    [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}

}  // namespace

Environment constantEnvironment(const glm::vec3& color) {
  Environment e;
  e.width = e.height = 1;
  e.rgb = {color.r, color.g, color.b};
  return e;
}

Environment loadEnvironment(const std::string& path) {
  Environment e;
  if (endsWith(path, ".exr")) {
    const Image img = readExr(path);
    e.width = img.width;
    e.height = img.height;
    e.rgb.resize(size_t(e.width) * e.height * 3);
    for (size_t i = 0; i < size_t(e.width) * e.height; ++i)
      for (int c = 0; c < 3; ++c) e.rgb[3 * i + c] = img.rgba[4 * i + c];
  } else if (endsWith(path, ".hdr") || endsWith(path, ".pic")) {
    const std::vector<uint8_t> bytes = readInputFile(path, kMaxImageFileBytes);
    std::string why;
    if (!decodeImageRgbFloat(bytes, &e.width, &e.height, &e.rgb, &why))
      throw InputError(path + ": cannot read the environment map: " + why);
  } else {
    throw InputError(path + ": an environment map must be .exr or .hdr");
  }
  if (e.width <= 0 || e.height <= 0) throw InputError(path + ": the environment map is empty");
  for (float v : e.rgb)
    if (!std::isfinite(v) || v < 0.0f)
      throw InputError(path + ": the environment map holds a negative or non-finite value");
  return e;
}

std::vector<float> environmentTables(const Environment& env, float* meanLuminance) {
  const size_t w = size_t(env.width), h = size_t(env.height);
  std::vector<float> out(env.rgb);
  out.reserve(3 * w * h + h * (w + 1) + h + 1);
  std::vector<double> rowSum(h, 0.0);
  double weighted = 0.0, solidAngle = 0.0;
  for (size_t j = 0; j < h; ++j) {
    // Each texel weighted by its luminance and the sine of its row (its share of the sphere).
    const double s = std::sin(M_PI * (double(j) + 0.5) / double(h));
    std::vector<double> cdf(w + 1, 0.0);
    for (size_t i = 0; i < w; ++i) {
      const double l = luminanceOf(&env.rgb[3 * (j * w + i)]) * s;
      cdf[i + 1] = cdf[i] + l;
    }
    rowSum[j] = cdf[w];
    weighted += cdf[w];
    solidAngle += s * double(w);
    for (size_t i = 0; i <= w; ++i)
      out.push_back(cdf[w] > 0.0 ? float(cdf[i] / cdf[w]) : float(double(i) / double(w)));
    out.back() = 1.0f;
  }
  double run = 0.0;
  out.push_back(0.0f);
  for (size_t j = 0; j < h; ++j) {
    run += rowSum[j];
    out.push_back(weighted > 0.0 ? float(run / weighted) : 0.0f);
  }
  if (weighted > 0.0) out.back() = 1.0f;
  *meanLuminance = solidAngle > 0.0 ? float(weighted / solidAngle) : 0.0f;
  return out;
}

float environmentUniformShare(const Environment& env, float meanLuminance) {
  const size_t texels = size_t(env.width) * size_t(env.height);
  if (texels == 0 || !(meanLuminance > 0.0f)) return 0.0f;
  double lowest = HUGE_VAL;
  for (size_t i = 0; i < texels; ++i) lowest = std::min(lowest, luminanceOf(&env.rgb[3 * i]));
  return float(std::clamp(lowest / double(meanLuminance), 0.0, 1.0));
}

}  // namespace pr
